"""Strict priorities: each level kept as well as the limits and the levels above let it, on
every backend, each answer checked; with no inequality active, every level is the nested
null-space baseline's; the baseline itself is the null-space oracle."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import solvers
from dvqp import (
    JogSegment,
    KinematicState,
    PointTask,
    PostureTask,
    PseudoinverseResolver,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    Task,
    TaskLevelError,
    TaskRows,
    ToolTask,
    jog_commands,
    simulate,
)
from dvqp.limits import JointPositionLimit, JointVelocityLimit, SurfaceHeight
from dvqp.resolution.pinv import pinv_step
from dvqp.resolution.spec import DEFAULT_TASK_WEIGHT
from dvqp.step import advance
from tests.common import LINK_LENGTHS, PIPE_RADIUS, Q0, objective_with, random_configurations
from tests.oracles.resolution import frames, kkt_residual, nested
from tests.resolution.test_qp_resolver import CorruptingBackend

DT = 0.005
AGREEMENT = {  # rad/s: how closely each backend's step meets the baseline's (its accuracy)
    "daqp": 1e-9,
    "quadprog": 1e-9,
    "proxqp": 1e-6,
    "osqp": 1e-6,
    "clarabel": 1e-6,
    "piqp": 1e-6,
    "highs": 1e-5,
}
BACKENDS = [b for b in solvers.available_backends() if b.removeprefix("qpsolvers:") in AGREEMENT]
START = frames(Robot.ndt13(LINK_LENGTHS), np.array(Q0), PIPE_RADIUS).guarded
FOUR = (
    ToolTask(("h", "alpha")),
    ToolTask(("l", "z"), priority=2),
    PointTask(1, ("h",), START[1], gain=1.0, priority=3),
    PointTask(3, ("z",), START[3], gain=1.0, priority=4),
)
"""Four levels that the arm meets together (6 rows of 13 joints): the tool's height and
heading, its place, body point 2's height and point 4's z where they start (0-based 1, 3)."""


def loose(robot: Robot) -> tuple:  # type: ignore[type-arg]
    """Limits that no slow motion near the start makes active."""
    return (JointPositionLimit(robot), JointVelocityLimit(robot), SurfaceHeight(-1.0))


def levels_of(spec: StepSpec, state: KinematicState, command: np.ndarray) -> list:  # type: ignore[type-arg]
    """Each level's ``(J, v)`` at ``state``, from the tasks' own rows."""
    found = []
    for level in spec.levels:
        rows = [task.compute(state, command, DT) for task in level]
        found.append(
            (np.vstack([r.jacobian for r in rows]), np.concatenate([r.velocity for r in rows]))
        )
    return found


@pytest.mark.parametrize("backend", BACKENDS)
def test_with_nothing_active_every_level_is_the_nested_baseline(robot: Robot, backend: str) -> None:
    """Level by level: the first k levels alone, k = 1 .. 4, at states round the start."""
    tol = AGREEMENT[backend.removeprefix("qpsolvers:")]
    objective = objective_with([])
    rng = np.random.default_rng(5)
    for k in range(1, 5):
        spec = StepSpec(FOUR[:k], objective, loose(robot))
        qp = Stepper(robot, PIPE_RADIUS, QPResolver(spec, backend), np.array(Q0), DT)
        pinv = Stepper(robot, PIPE_RADIUS, PseudoinverseResolver(spec), np.array(Q0), DT)
        qp.start(np.array(Q0))
        pinv.start(np.array(Q0))
        for q in random_configurations(3, seed=k, spread=0.03):
            command = 0.02 * rng.normal(size=4)
            assert qp.load(q) and pinv.load(q)
            found = qp.resolve(command, DT)
            assert found.status == "optimal", found.status
            p = qp.problem()
            assert np.all(p.G @ qp.x < p.h - 1e-4) and np.all(p.lb + 1e-3 < qp.x)
            assert np.all(qp.x < p.ub - 1e-3)  # nothing active
            pinv.resolve(command, DT)
            state = KinematicState.compute(robot, q, PIPE_RADIUS)
            expected = nested(
                levels_of(spec, state, command), objective_gradient(pinv), np.ones(13)
            )
            np.testing.assert_allclose(pinv.x, expected, atol=1e-9, rtol=0)
            np.testing.assert_allclose(qp.x, pinv.x, atol=tol, rtol=0)


def objective_gradient(stepper: Stepper) -> np.ndarray:
    """``g = λ ∂w/∂Q`` of the loaded state."""
    return stepper.arrays.objective.gain * stepper.objective.gradient


@pytest.mark.parametrize("backend", BACKENDS)
def test_with_four_levels_a_run_is_the_baseline_step_for_step_and_holds_the_points(
    robot: Robot, backend: str
) -> None:
    spec = StepSpec(FOUR, objective_with([]), loose(robot))
    commands = jog_commands(
        [JogSegment(0.5, np.array([0.02, 0.01, 0.0, 0.05])), JogSegment(0.3, np.zeros(4))], DT
    )
    runs = {
        name: simulate(robot, PIPE_RADIUS, resolver, np.array(Q0), commands, DT, verify=True)
        for name, resolver in (
            ("pinv", PseudoinverseResolver(spec)),
            ("qp", QPResolver(spec, backend)),
        )
    }
    qp, base = runs["qp"], runs["pinv"]
    assert qp.ok and set(qp.status) == {"optimal"} and qp.levels == base.levels
    assert len(qp.levels) == 4
    np.testing.assert_allclose(qp.q, base.q, atol=1e-6, rtol=0)  # rad, every sample
    assert qp.level_error.max() < 1e-6
    held = qp.points - qp.points[0]
    assert np.abs(held[:, 1, 2]).max() < 1e-4  # point 2's height, m (0-based 1)
    assert np.abs(held[:, 3, 1]).max() < 1e-4  # point 4's z, m
    assert np.ptp(qp.tool[:, 0]) > 0.009  # while the tool moved on 1 cm


def limited_robot() -> Robot:
    lim = np.r_[np.inf, np.full(12, 1.2)]
    return Robot.ndt13(LINK_LENGTHS, q_min=-lim, q_max=lim, qd_max=1.0)


@pytest.mark.parametrize(
    "backend", [b for b in ("daqp", "osqp", "clarabel", "proxqp") if b in BACKENDS]
)
def test_a_level_the_limits_forbid_gives_way_and_the_level_above_is_kept(backend: str) -> None:
    robot = limited_robot()
    limits = (JointPositionLimit(robot), JointVelocityLimit(robot))
    two = StepSpec(
        (ToolTask(("h", "alpha")), ToolTask(("l", "z"), priority=2)), objective_with([]), limits
    )
    one = StepSpec((ToolTask(),), objective_with([]), limits)
    command = np.array([2.0, 0.0, 0.0, 0.0])  # 2 m/s along the weld: more than the joints give
    for spec, kept in ((two, True), (one, False)):
        s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, backend), np.array(Q0), DT)
        s.start(np.array(Q0))
        found = s.resolve(command, DT)
        assert found.success and found.status == "relaxed"
        x = s.x.copy()
        p = s.problem()
        height_and_heading = p.A[:2] @ x - p.b[:2] if kept else p.A[2:] @ x - p.b[2:]
        assert (np.abs(height_and_heading).max() <= 1e-6) == kept
        assert s.move()
        if kept:
            assert s.level_error[0] <= 1e-6 < 0.1 < s.level_error[1]
            # the lower level: the minimiser of ½ρ‖A₂Q̇ − b₂‖² + the cost, level 1 exact
            A1, b1, A2, b2 = p.A[:2], p.b[:2], p.A[2:], p.b[2:]
            rho = DEFAULT_TASK_WEIGHT
            residual = kkt_residual(
                p.P + rho * A2.T @ A2, p.q - rho * A2.T @ b2, A1, b1, p.G, p.h, p.lb, p.ub, x
            )
            assert residual < 1e-6


def test_a_level_beyond_the_joints_left_is_met_in_least_squares_without_giving_way(
    robot: Robot,
) -> None:
    """A posture below two tool levels (4 + 13 rows for 13 joints) is never met exactly, and
    no limit binds: the step is the lexicographic minimiser (the SVD oracle's: each level in
    least squares in what those above leave free), ``optimal``, not relaxed."""
    posture = PostureTask(np.array(Q0) + 0.05, gain=1.0, priority=3, weight=0.5)
    spec = StepSpec((*FOUR[:2], posture), objective_with([]), loose(robot))
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), np.array(Q0), DT)
    s.start(np.array(Q0))
    command = np.array([0.01, -0.01, 0.0, 0.05])
    found = s.resolve(command, DT)
    assert found.status == "optimal"  # met in least squares: nothing gave way
    p = s.problem()
    g = objective_gradient(s)
    levels = [(p.A[:2], p.b[:2]), (p.A[2:4], p.b[2:4]), (p.A[4:], p.b[4:])]
    np.testing.assert_allclose(s.x, nested(levels, g, np.ones(13)), atol=1e-9)
    assert s.move() and s.level_error[0] < 1e-9 and s.level_error[1] < 1e-9
    assert s.level_error[2] > 1e-3  # the posture: in least squares


class CorruptRelaxed(CorruptingBackend):
    """DAQP whose answers to a level's relaxed QP (a slack column: more than 13 variables) are
    shifted: the residual check must refuse them."""

    def solve(
        self, problem: solvers.Problem, initvals: np.ndarray | None = None
    ) -> solvers.Solution:
        if problem.n == 13:
            return self._inner.solve(problem, initvals)
        return super().solve(problem, initvals)


def test_a_level_answer_that_fails_its_check_is_not_used(robot: Robot) -> None:
    """The lower level's relaxed answers are all wrong: the step is the level above's answer
    (every limit and level 1 kept), and the refusals are counted."""
    robot = limited_robot()
    limits = (JointPositionLimit(robot), JointVelocityLimit(robot))
    spec = StepSpec(
        (ToolTask(("h", "alpha")), ToolTask(("l", "z"), priority=2)), objective_with([]), limits
    )
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, CorruptRelaxed), np.array(Q0), DT)
    s.start(np.array(Q0))
    moved = advance(s, np.array([2.0, 0.0, 0.0, 0.0]), DT)
    assert moved.step.success and moved.step.status == "relaxed"
    assert moved.step.level_error[0] <= 1e-6  # type: ignore[index]
    assert s.solver is not None and sum(s.solver.refusals.values()) >= 2  # strict and relaxed


def test_the_baseline_meets_a_level_it_cannot_meet_exactly_in_least_squares(robot: Robot) -> None:
    """The tool's h twice, at two priorities: level 2 has nothing left to move, so it keeps
    the error level 1 left it (here none), undamped as damped."""
    spec = StepSpec((ToolTask(), ToolTask(("h",), priority=2)), objective_with([]))
    s = Stepper(robot, PIPE_RADIUS, PseudoinverseResolver(spec), np.array(Q0), DT)
    s.start(np.array(Q0))
    command = np.array([0.01, 0.0, 0.0, 0.0])
    assert s.resolve(command, DT).success
    tool = np.array(s.state.tool_jacobian)
    np.testing.assert_allclose(tool @ s.x, command, atol=1e-10)
    damped = Stepper(robot, PIPE_RADIUS, PseudoinverseResolver(spec, 0.01), np.array(Q0), DT)
    damped.start(np.array(Q0))
    assert damped.resolve(command, DT).success


@pytest.mark.parametrize(
    ("tasks", "words"),
    [
        (
            (ToolTask(), PostureTask(), PointTask(1, priority=2)),
            "level 1 (tool; posture) cannot be met even alone: it has 17 rows for 13 joints",
        ),
        (
            (ToolTask(("l",)), ToolTask(("h", "l")), PointTask(1, priority=2)),
            "level 1 (tool l; tool l, h) cannot be met even alone: "
            "its 3 rows are dependent at the start (rank 2)",
        ),
    ],
)
def test_a_level_that_cannot_be_met_even_alone_is_refused(
    robot: Robot, tasks: tuple, words: str
) -> None:  # type: ignore[type-arg]
    spec = StepSpec(tasks, objective_with([]))
    for resolver in (QPResolver(spec, "daqp"), PseudoinverseResolver(spec)):
        with pytest.raises(TaskLevelError) as info:
            Stepper(robot, PIPE_RADIUS, resolver, np.array(Q0), DT)
        assert str(info.value) == f"tasks: {words}" and info.value.level == 1


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.lists(st.integers(1, 3), min_size=1, max_size=4), st.booleans())
def test_the_compiled_nested_step_is_the_null_space_oracle(
    seed: int, sizes: list[int], weighted: bool
) -> None:
    rng = np.random.default_rng(seed)
    n = 13
    rows = [rng.normal(size=(m, n)) for m in sizes]  # independent: every level met
    v = [rng.normal(size=m) for m in sizes]
    g, w = rng.normal(size=n), rng.uniform(0.3, 3.0, n) if weighted else np.ones(n)
    A, b = np.vstack(rows), np.concatenate(v)
    breaks = np.cumsum([0, *sizes]).astype(np.int64)
    out, info = np.zeros(n), np.zeros(3)
    status = pinv_step(A, b, breaks, np.ones(b.shape[0]), -g, w, np.eye(n), False, 0.0, info, out)
    assert status == -1
    np.testing.assert_allclose(out, nested(list(zip(rows, v, strict=True)), g, w), atol=1e-9)
    np.testing.assert_allclose(A @ out, b, atol=1e-9)  # every level met
    dense = np.diag(w)  # the same metric, written out: the dense path
    status = pinv_step(A, b, breaks, np.ones(b.shape[0]), -g, w, dense, True, 0.0, info, out)
    np.testing.assert_allclose(out, nested(list(zip(rows, v, strict=True)), g, w), atol=1e-9)


class Lean(Task):
    """A user's hard task in NumPy: joint ``i`` at ``speed`` rad/s."""

    name = "lean"

    def __init__(self, i: int, speed: float, priority: int) -> None:
        self.i, self.speed, self.priority = i, speed, priority

    def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
        return TaskRows(np.eye(1, state.n, self.i), np.array([self.speed]))


@pytest.mark.parametrize("backend", [b for b in ("daqp", "osqp") if b in BACKENDS])
def test_a_users_task_joins_a_level_like_a_built_in(robot: Robot, backend: str) -> None:
    tasks = (*FOUR[:2], Lean(4, 0.05, priority=2), Lean(8, -0.03, priority=3))
    spec = StepSpec(tasks, objective_with([]), loose(robot))
    assert spec.level_names == ("tool h, alpha", "tool l, z; lean", "lean")
    qp = Stepper(robot, PIPE_RADIUS, QPResolver(spec, backend), np.array(Q0), DT)
    pinv = Stepper(robot, PIPE_RADIUS, PseudoinverseResolver(spec), np.array(Q0), DT)
    qp.start(np.array(Q0))
    pinv.start(np.array(Q0))
    command = np.array([0.01, 0.005, 0.0, 0.02])
    assert qp.resolve(command, DT).status == "optimal"
    pinv.resolve(command, DT)
    np.testing.assert_allclose(qp.x, pinv.x, atol=AGREEMENT[backend])
    assert qp.x[4] == pytest.approx(0.05, abs=1e-6) and qp.x[8] == pytest.approx(-0.03, abs=1e-6)
    np.testing.assert_array_equal(qp.layout.tasks.levels, [0, 2, 5, 6])  # rows by level
