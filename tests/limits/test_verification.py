"""The step's exact verification: the worst excess of every limit (dvqp's and a user's dampers)
at a configuration, against the values measured independently and the old rule
(:func:`tests.oracles.limits.worst_excess`)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest

from dvqp import Distances, KinematicState, Limit, QPResolver, Robot, Stepper, VelocityDamper
from dvqp.geometry.bend import PRECISION
from dvqp.limits import JointPositionLimit, ObstacleDamper, ProbeHeight, TiltLimit
from tests import stepping
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.limit_fixtures import DT, ROOT, SCENES, configurations, scene, tight_limits
from tests.oracles.limits import assert_excess, measure, verified, worst_excess
from tests.oracles.resolution import verified_values
from tests.oracles.resolution import worst_excess as true_excess


def walks(found: Sequence[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Every configuration from each of the first three, and back to the first."""
    return [(a, b) for a in found[:3] for b in found] + [(b, found[0]) for b in found]


def assert_verification(
    s: Stepper, limits: Sequence[Limit], pairs: Sequence[tuple], radius: float = PIPE_RADIUS
) -> None:
    """From each start, the stepper's worst excess at each configuration is the oracle's."""
    robot = s.robot
    for start, q in pairs:
        s.start(start)
        assert s.load(q)
        at_start = KinematicState.compute(robot, start, radius)
        now = KinematicState.compute(robot, q, radius)
        want = worst_excess(limits, at_start, now)
        found = s.excess()
        assert_excess(found, want)
        assert s.broken == want.broken
        np.testing.assert_array_equal(s.excess_now, [found.value, found.ratio])


@pytest.mark.parametrize("name", SCENES)
def test_a_scene_s_verification_is_its_worst_excess(name: str) -> None:
    sc = scene(name)
    found = configurations(sc.robot, sc.q0, 8, seed=7, spread=SCENES[name], radius=sc.pipe_radius)
    s = Stepper(sc.robot, sc.pipe_radius, QPResolver(sc.spec(), "daqp"), sc.q0, DT)
    pairs = walks(found)
    assert_verification(s, sc.spec().limits, pairs, sc.pipe_radius)
    s.start(found[0])
    assert any(s.load(q) and s.broken for q in found[1:])  # some walks break a limit


@pytest.mark.parametrize("deceleration", [1.0, math.inf])
def test_starts_inside_the_margins_keep_their_floor(
    robot: Robot, q0: np.ndarray, state0: KinematicState, deceleration: float
) -> None:
    """Parts that start deep inside an obstacle, below their heights, tilted or folded closer
    than their margins: the floor is the start's value."""
    limits = (*tight_limits(state0, deceleration), JointPositionLimit(robot))
    s = stepping.stepper(robot, q0, limits=limits)
    assert_verification(s, limits, walks([q0, *configurations(robot, q0, 6, seed=8, spread=0.1)]))
    deep = 0
    for limit in limits:
        values = verified(limit, state0)
        assert values is not None
        deep += int(np.sum(values.values < values.safe - 0.01))
    assert deep > 0  # some part starts deep inside its margin
    s.start(q0)
    assert s.excess().value == pytest.approx(0.0, abs=1e-15)  # at its start: on its floor


def test_joint_positions_with_infinite_and_crossed_limits(q0: np.ndarray) -> None:
    q_min, q_max = q0 - 0.1, q0 + 0.1
    q_min[0], q_max[3] = -np.inf, np.inf
    q_min[5], q_max[5] = -np.inf, np.inf
    limited = Robot.ndt13(LINK_LENGTHS, q_min=q_min, q_max=q_max)
    limits = (JointPositionLimit(limited),)
    s = stepping.stepper(limited, q0, limits=limits)
    found = configurations(limited, q0, 6, seed=9, spread=0.2)  # starts past some limits
    assert any(np.any((q < q_min) | (q > q_max)) for q in found[:3])
    assert_verification(s, limits, walks(found))
    free = Robot.ndt13(LINK_LENGTHS, q_min=np.full(13, -np.inf), q_max=np.full(13, np.inf))
    s = stepping.stepper(free, q0, limits=[JointPositionLimit(free)])
    for q in configurations(free, q0, 3, seed=10, spread=0.2):
        assert s.load(q) and s.excess().value == -math.inf and not s.broken


def test_the_tilt_is_folded_into_zero_to_a_right_angle(robot: Robot, q0: np.ndarray) -> None:
    limits = (TiltLimit(0.3), TiltLimit(1.4), ProbeHeight(0.5))
    found = [q0, *configurations(robot, q0, 8, seed=11, spread=0.8)]
    s = stepping.stepper(robot, q0, limits=limits)
    assert_verification(s, limits, walks(found))
    floors = s.arrays.checks.safe  # the tilt limits' safe values are their angles
    assert floors[:2] == pytest.approx([0.3, 1.4], abs=1e-15)


def expected_rows(limit: object, k: int, pairs: int, rail: bool, base: bool = False) -> int:
    """How many rows of ``G`` (and verified values) one of dvqp's dampers adds (k body points,
    the lead point and link if ``rail``: the rail's carriage link, or with ``base`` the base
    link of an arm standing on the pipe, which keeps the surface, not the body's height)."""
    if isinstance(limit, ObstacleDamper):
        return len(limit.obstacles) * (2 * k + 1 + 2 * rail)
    if isinstance(limit, TiltLimit):
        return int(limit.min_tilt > 0.0)
    # heights: the points, then the link chords (body links and carriage; the holder)
    rows = {"SurfaceHeight": 2 * k - 1 + (rail and not base), "ProbeHeight": 2}
    rows["SelfCollision"] = pairs
    return {**rows, "BaseHeight": 2}[type(limit).__name__]


def test_every_bundled_scene_s_limits_are_in_its_step() -> None:
    """Each damper of each bundled scene adds its rows and verified values, unless it adds
    nothing (no obstacles, ``min_tilt = 0``); a position limit verifies the joint room."""
    for path in sorted((ROOT / "scenes").glob("*.toml")):
        sc = scene(path.stem)
        k = sc.robot.n_points
        limits = sc.spec().limits
        s = Stepper(sc.robot, sc.pipe_radius, QPResolver(sc.spec(), "daqp"), sc.q0, DT)
        s.start(sc.q0)
        s.prepare(np.zeros(4), DT)
        dampers = [lim for lim in limits if isinstance(lim, VelocityDamper)]
        rail = sc.robot.has_rail  # the carriage link: against every link but link 1
        pairs = k * (k - 1) // 2 - (k - 1) + (k - 1) * rail
        base = sc.robot.base_frame is not None
        rows = sum(expected_rows(lim, k, pairs, rail, base) for lim in dampers)
        G = s.problem().G
        assert (0 if G is None else G.shape[0]) == rows, path.stem
        joints = 2 * sc.robot.n * any(isinstance(lim, JointPositionLimit) for lim in limits)
        assert s.arrays.checks.values.shape[0] == rows + joints, path.stem
        start = KinematicState.compute(sc.robot, sc.q0, sc.pipe_radius)
        if any(o.bounded for o in sc.obstacles):  # solids: against their true clearances
            values = verified_values(limits, sc.robot, np.asarray(sc.q0, float), sc.pipe_radius)
            value, _, quantity = true_excess(values, values)
            found = s.excess()
            assert found.quantity == quantity and abs(found.value - value) <= PRECISION, found
        else:
            assert_excess(s.excess(), worst_excess(limits, start, start))


class Floors(VelocityDamper):
    """A user's damper: each body point above its own floor (safe values per row)."""

    name = "floors"
    quantity = "height"

    def __init__(self, floors: np.ndarray) -> None:
        super().__init__()
        self.floors = floors

    def distances(self, state: KinematicState) -> Distances:
        k = state.k
        return Distances(
            np.array(state.points[:, 2]),
            np.array(state.point_jacobians[:, 2]),
            self.floors,
            lambda: tuple(f"floor{i + 1}" for i in range(k)),
        )


def test_a_user_s_damper_is_verified_as_dvqp_s_are(robot: Robot, q0: np.ndarray) -> None:
    """Its distances are verified against ``min(safe, value at the start)`` next to dvqp's
    limits, the worst named by its labels."""
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    heights = np.array(state.points[:, 2])
    floors = Floors(heights + np.array([-0.05, -0.05, -0.05, 0.01, -0.05]))  # point 4 below
    limits = (*tight_limits(state, 1.0), floors, JointPositionLimit(robot))
    s = stepping.stepper(robot, q0, limits=limits)
    found = [q0, *configurations(robot, q0, 6, seed=12, spread=0.1)]
    assert_verification(s, limits, walks(found))
    assert measure(floors, state).value.shape == (5,)
    low = q0.copy()
    low[4] += 0.2  # points 4 and 5 go down 3 and 5.5 cm
    lower = KinematicState.compute(robot, low, PIPE_RADIUS).points[:, 2]
    assert lower[3] < heights[3] - 0.025 and lower[4] < heights[4] - 0.05
    user = stepping.excess([floors], robot, q0, low)
    assert user.broken and user.label == "floor4" and user.quantity == "height"
    assert user.bound == pytest.approx(heights[3], abs=1e-15)  # started below its floor
    assert user.value == pytest.approx(heights[3] - lower[3], abs=1e-15)
