"""The step's limits write their rows and box into one problem: dvqp's compiled limits and a
user's NumPy (or compiled) limits side by side, each against what it keeps, measured
independently (:mod:`tests.oracles.limits`)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest
from numba import njit

from dvqp import (
    Bounds,
    Constraint,
    Distances,
    Kernel,
    KinematicState,
    Limit,
    Objective,
    ObjectiveTerm,
    ObstacleSet,
    QPResolver,
    Robot,
    Stepper,
    StepPlan,
    Term,
    VelocityDamper,
)
from dvqp.limits import (
    AccelerationLimit,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    SurfaceHeight,
    TiltLimit,
    damper_value,
)
from dvqp.limits.self_collision import pair_distances
from dvqp.objective import ObstaclePoints, OrbitalLevel
from dvqp.workspace import PairBuffers, PartNames, as_struct
from tests import stepping
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.limit_fixtures import (
    DT,
    DTS,
    SCENES,
    configurations,
    damper_rows,
    near_obstacles,
    problem_rows,
    scene,
    tight_limits,
)
from tests.oracles.limits import damper_rhs, joint_box, segment_distance
from tests.oracles.objective import total


def assert_problem(
    s: Stepper, limits: Sequence[Limit], dt: float, *, fd: bool = False, gradient: bool = True
) -> int:
    """At the loaded state, every damper's rows are what it keeps (:func:`damper_rows`), the
    box is the joint limits' (and a user's boxes'), and the problem holds exactly these rows
    (damper rows first, in the spec's order, then the other limits' rows; a row that does not
    apply is ``0 · Q̇ ≤ +inf``). Returns the rows that apply."""
    q = s.state.q.copy()
    rows = [
        damper_rows(s, limit, q, dt, fd=fd, atol=1e-9, gradient=gradient)
        for limit in limits
        if isinstance(limit, VelocityDamper)
    ]
    s.load(q)
    s.prepare(np.zeros(4), dt)
    rows += [s.rows(limit) for limit in limits if isinstance(limit, Cap)]
    lb, ub = joint_box(limits, q, dt)
    for limit in limits:
        if isinstance(limit, Box):
            low, high = limit.compute(s.state, dt).lb, limit.compute(s.state, dt).ub
            lb, ub = np.maximum(lb, low), np.minimum(ub, high)
    problem = s.problem()
    np.testing.assert_array_equal(problem.lb, lb)
    np.testing.assert_array_equal(problem.ub, ub)
    if problem.G is None:
        assert not rows or not sum(r.rows for r in rows)  # type: ignore[union-attr]
        return 0
    applies = np.isfinite(problem.h)
    assert np.all(problem.G[~applies] == 0.0)
    np.testing.assert_array_equal(problem.G[applies], np.vstack([r.G for r in rows]))  # type: ignore[union-attr]
    np.testing.assert_array_equal(problem.h[applies], np.concatenate([r.h for r in rows]))  # type: ignore[union-attr]
    return int(applies.sum())


@pytest.mark.parametrize("name", SCENES)
def test_a_scene_s_limits_write_the_rows_of_what_they_keep(name: str) -> None:
    sc = scene(name)
    limits = sc.spec().limits
    found = configurations(sc.robot, sc.q0, 12, seed=1, spread=SCENES[name], radius=sc.pipe_radius)
    assert len(found) >= 6
    s = Stepper(sc.robot, sc.pipe_radius, QPResolver(sc.spec(), "daqp"), sc.q0, DT)
    s.start(sc.q0)
    active = []
    for i, q in enumerate(found):
        assert s.load(q)
        for dt in DTS:
            active.append(assert_problem(s, limits, dt, fd=i == 0, gradient=dt == DTS[0]))
    assert min(active) < max(active) or not len(sc.obstacles)  # rows come and go in place


@pytest.mark.parametrize("deceleration", [1.0, 0.05, math.inf])
def test_the_dampers_rows_inside_and_outside_their_margins(
    robot: Robot, q0: np.ndarray, state0: KinematicState, deceleration: float
) -> None:
    limits = tight_limits(state0, deceleration)
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    for q in [q0, *configurations(robot, q0, 10, seed=2, spread=0.15)]:
        assert s.load(q)
        for dt in DTS:
            assert assert_problem(s, limits, dt, fd=q is q0 and dt == DT, gradient=dt == DT) > 0
    s.load(q0)
    s.prepare(np.zeros(4), DT)
    h = s.problem().h
    assert np.any(h == 0.0) and np.any(h < 0.0) and np.any((h > 0.0) & (h < np.inf))


def test_limits_that_add_nothing_add_no_rows_and_no_values(robot: Robot, q0: np.ndarray) -> None:
    limits = [TiltLimit(0.0), ObstacleDamper(ObstacleSet([]))]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    assert s.prepare(np.zeros(4), DT) == -1
    assert s.problem().G is None and problem_rows(s) == 0
    assert s.excess().value == -math.inf and s.excess_now[0] == -math.inf


def test_the_arm_s_link_pairs_are_the_brute_force_pairs(robot: Robot, q0: np.ndarray) -> None:
    pairs = PairBuffers.allocate(5)
    for q in [q0, *configurations(robot, q0, 5, seed=5, spread=0.6)]:
        o = np.array(KinematicState.compute(robot, q, PIPE_RADIUS).origins)
        pair_distances(o, as_struct(pairs))
        i, j = pairs.i, pairs.j
        brute, _ = segment_distance(o[i], o[i + 1], o[j], o[j + 1])
        np.testing.assert_allclose(pairs.distance, brute, rtol=0, atol=1e-12)
        s, t = pairs.s[:, None], pairs.t[:, None]
        gap = (o[i] + s * (o[i + 1] - o[i])) - (o[j] + t * (o[j + 1] - o[j]))
        np.testing.assert_allclose(np.linalg.norm(gap, axis=1), pairs.distance, atol=1e-15)
        np.testing.assert_allclose(pairs.normal * pairs.distance[:, None], gap, atol=1e-15)


def test_the_scalar_damper_value_is_the_old_damper_rhs_bit_for_bit() -> None:
    rng = np.random.default_rng(6)
    safe, depth = 0.01, 1e-4
    d = np.concatenate(
        [
            safe + rng.uniform(-0.05, 0.2, 500),
            safe + rng.uniform(-2e-4, 2e-4, 500),
            [safe, safe - depth, safe + depth, np.nextafter(safe - depth, 0.0), -1.0],
        ]
    )
    for gain in (0.1, 0.5, 1.0):
        for dt in (1e-3, 0.005, 0.1):
            for decel in (math.inf, 1.0, 0.2, 1e-3):
                want = damper_rhs(d, safe, gain, dt, depth, decel)
                got = np.array([damper_value(x, safe, gain, dt, depth, decel) for x in d])
                np.testing.assert_array_equal(got, want)


# -- a user's limits in the same problem --------------------------------------------------


class Mine(VelocityDamper):
    """A user's damper in NumPy: body points 2 and 4 above their own floors."""

    name = "mine"

    def __init__(self, floors: Sequence[float]) -> None:
        super().__init__(gain=0.4, deceleration=2.0)
        self.floors = np.array(floors)

    def distances(self, state: KinematicState) -> Distances:
        at = [1, 3]
        return Distances(
            np.array(state.guarded[at, 2]),
            np.array(state.guarded_jacobians[at, 2]),
            self.floors,
            lambda: ("mine/point2", "mine/point4"),
        )


@njit(cache=True)
def _tool_z(tool, tool_jacobian, distance, gradient, usable):  # type: ignore[no-untyped-def]
    distance[0], usable[0] = tool[1], True
    for c in range(gradient.shape[1]):
        gradient[0, c] = tool_jacobian[1, c]


class Compiled(VelocityDamper):
    """A user's damper with a kernel: the tool's z above a bound (its NumPy ``distances``
    is the oracle)."""

    name = "z"
    reach = 0.5

    def __init__(self, z_min: float) -> None:
        super().__init__(gain=0.6)
        self.z_min = z_min

    @property
    def safe(self) -> float:
        return self.z_min

    def labels(self, names: PartNames) -> tuple[str, ...]:
        return ("tool/z",)

    def kernel(self, plan: StepPlan) -> Kernel:
        distance, gradient, usable = plan.damper_rows(1)
        s = plan.state
        return Kernel(_tool_z, (s.tool, s.tool_jacobian, distance, gradient, usable))

    def distances(self, state: KinematicState) -> Distances:
        return Distances(state.tool[1:2], state.tool_jacobian[1:2], self.z_min, lambda: ("tool/z",))


class Cap(Limit):
    """A user's constraint: joints 2 + 3 turn together at most 0.3 rad/s, and joint 2 no
    faster than 0.2 rad/s while it is negative (a row that comes and goes: the run reserves
    the rows it has at its start)."""

    name = "cap"

    def compute(self, state: KinematicState, dt: float) -> Constraint:
        G = np.zeros((2, state.n))
        G[0, 1:3] = 1.0
        G[1, 1] = 1.0
        if state.q[1] < 0.0:
            return Constraint(G, np.array([0.3, 0.2]))
        return Constraint(G[:1], np.array([0.3]))


class Box(Limit):
    """A user's box: every joint within 0.4 rad/s, the wrist joints within 0.1 + |q| rad/s."""

    name = "box"

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        ub = np.full(state.n, 0.4)
        ub[10:] = 0.1 + np.abs(state.q[10:])
        return Bounds(-ub, ub)


class Lean(ObjectiveTerm):
    """A user's objective term: ``w = −½ (q₂ − 0.02)²``."""

    name = "lean"

    def evaluate(self, state: KinematicState) -> Term:
        gradient = np.zeros(state.n)
        gradient[1] = -(state.q[1] - 0.02)
        return Term(-0.5 * float(state.q[1] - 0.02) ** 2, gradient)


def test_a_user_s_limits_land_in_the_same_problem_as_dvqp_s(q0: np.ndarray) -> None:
    """A user's dampers (NumPy and compiled), constraint, box and objective term, between
    dvqp's: every row, the box and the cost of one problem, which the step solves."""
    robot = Robot.ndt13(LINK_LENGTHS, q_min=q0 - 0.3, q_max=q0 + 0.3)
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    heights = np.array(state.guarded[[1, 3], 2])
    obstacles = near_obstacles(state)
    objective = Objective((OrbitalLevel(0.08, 50.0), Lean(), ObstaclePoints(obstacles)), 0.5)
    cap = Cap()
    limits = (
        Mine(heights - [0.02, 1e-5]),
        ObstacleDamper(obstacles, margin=0.01, influence=0.1),
        cap,
        JointPositionLimit(robot),
        Compiled(float(state.tool[1]) - 0.05),
        Box(),
        SurfaceHeight(0.02),
        JointVelocityLimit(robot),
        AccelerationLimit(robot, 20.0),
    )
    s = stepping.stepper(robot, q0, limits=limits, objective=objective, backend="daqp")
    signs = set()
    for q in [q0, *configurations(robot, q0, 6, seed=7, spread=0.1)]:
        assert s.load(q)
        signs.add(bool(q[1] > 0.0))
        for dt in (DT, 0.02):
            assert assert_problem(s, limits, dt, fd=q is q0) > 0
            found = cap.compute(s.state, dt)
            rows = s.rows(cap)
            np.testing.assert_array_equal(rows.G, found.G)  # type: ignore[union-attr]
            np.testing.assert_array_equal(rows.h, found.h)  # type: ignore[union-attr]
        want = total(objective.terms, KinematicState.compute(robot, q, PIPE_RADIUS))
        assert s.objective.value == pytest.approx(want.value, rel=0, abs=1e-12)
        found = s.resolve(np.array([0.01, 0.0, 0.0, 0.0]), DT)
        problem = s.problem()
        np.testing.assert_allclose(problem.q, -0.5 * want.gradient, rtol=0, atol=1e-12)
        assert found.success and np.all(problem.G @ s.x <= problem.h + 1e-9)
        assert np.all(problem.lb - 1e-9 <= s.x) and np.all(s.x <= problem.ub + 1e-9)
        s.observe(s.x, DT)
    assert signs == {True, False}  # the user's second row came and went
