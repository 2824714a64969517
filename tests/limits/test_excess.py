"""Exact verification of a configuration against the limits: the worst excess and its words."""

import math

import numpy as np
import pytest

from dvqp import Distances, KinematicState, Obstacle, ObstacleSet, Robot, VelocityDamper
from dvqp.geometry import proximity
from dvqp.limits import (
    NO_EXCESS,
    Excess,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    SurfaceHeight,
)
from dvqp.limits.excess import worst_excess
from tests import stepping
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.oracles.limits import assert_excess
from tests.oracles.limits import worst_excess as oracle_worst


def test_the_worst_excess_is_the_largest_relative_to_its_tolerance(
    robot: Robot, q0: np.ndarray
) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    lowest = float(start.points[:, 2].min())
    point = start.points[2, :2]
    obstacles = ObstacleSet([Obstacle(point + np.array([0.0, 0.05]), 0.03)])
    height = SurfaceHeight(min_height=lowest - 0.0005)  # kept, 0.5 mm of room
    damper = ObstacleDamper(obstacles, margin=0.03)  # 2 cm inside at the start: floor = start
    q = q0.copy()
    q[1] += 0.02
    limits = [height, damper, JointVelocityLimit(robot)]
    worst = stepping.excess(limits, robot, q0, q)
    parts = [stepping.excess([height], robot, q0, q), stepping.excess([damper], robot, q0, q)]
    assert worst == max(parts, key=lambda e: e.ratio)
    assert parts[0].value != parts[1].value
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    assert_excess(worst, oracle_worst(limits, start, moved))


def test_a_clearance_below_the_start_is_broken_and_described(robot: Robot, q0: np.ndarray) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    q = q0.copy()
    q[12] += 0.3  # swing the probe
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    # a small circle where the probe ends, clear of the whole arm at the start
    obstacle = Obstacle(moved.tool[:2] + np.array([0.0, 0.002]), 0.004)
    damper = ObstacleDamper(ObstacleSet([obstacle]), margin=0.001)
    s = stepping.stepper(robot, q0, limits=[damper])
    assert not s.broken and not s.excess().broken
    assert s.load(q) and s.broken
    found = s.excess()
    assert found.broken and found.label == "probe/obstacles[0]" and found.unit == "m"
    assert found.quantity == "clearance" and found.tolerance == 1e-4
    assert found.actual == pytest.approx(-0.002, abs=1e-9)
    start_clearance = proximity(start, damper.obstacles).point_clearance[0, 5]  # the probe
    assert found.bound == pytest.approx(min(0.001, start_clearance))
    assert found.describe().startswith("probe/obstacles[0] clearance -0.002 m < ")
    np.testing.assert_allclose(s.excess_now, [found.value, found.value / 1e-4], rtol=1e-12)
    assert_excess(found, oracle_worst([damper], start, moved))


def test_joint_excess_names_the_joint_and_allows_a_start_outside(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    q[4] = 0.6  # starts 0.1 rad out
    limit = JointPositionLimit(robot)
    assert not stepping.excess([limit], robot, q, q).broken
    q2 = q.copy()
    q2[4] = 0.61
    found = stepping.excess([limit], robot, q, q2)
    assert found.broken and found.label == "joint5"
    assert found.quantity == "joint position" and found.unit == "rad"
    assert found.value == pytest.approx(0.01) and found.bound == pytest.approx(0.6)
    assert found.actual == 0.61 and found.tolerance == 1e-6
    assert found.describe().startswith("joint5 joint position 0.61 rad past 0.6 rad")
    q3 = q.copy()
    q3[7] = -0.52  # past the lower limit
    found = stepping.excess([limit], robot, q, q3)
    assert found.label == "joint8" and found.bound == pytest.approx(-0.5)
    assert found.value == pytest.approx(0.02)


def test_the_start_s_floors_are_set_by_start(robot: Robot, q0: np.ndarray) -> None:
    """The floors are ``min(safe, value at the start)`` of the run that starts last."""
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    height = SurfaceHeight(min_height=float(state.points[:, 2].max()) + 0.01)  # all start below
    s = stepping.stepper(robot, q0, limits=[height])
    assert s.excess().value == pytest.approx(0.0, abs=1e-15)
    lower = q0.copy()
    lower[1] += 0.05
    assert s.load(lower) and s.broken  # lower than the start
    s.start(lower)
    assert not s.broken and s.excess().value == pytest.approx(0.0, abs=1e-15)
    assert s.load(q0) and not s.broken  # higher than the new start


def test_nothing_to_verify_is_no_excess(robot: Robot, q0: np.ndarray) -> None:
    s = stepping.stepper(robot, q0, limits=[JointVelocityLimit(robot)])
    assert s.excess() == NO_EXCESS and not s.broken


def test_describe_reads_as_one_line() -> None:
    e = Excess(0.0038, 1e-4, "probe/obstacles[2]", "clearance", "m", 0.0062, 0.01)
    assert e.describe() == "probe/obstacles[2] clearance 0.0062 m < 0.01 m (by 3.8 mm)"
    tilt = Excess(0.05, 1e-3, "probe/tilt", "tilt", "rad", 0.15, 0.2)
    assert tilt.describe() == "probe/tilt tilt 0.15 rad < 0.2 rad (by 0.05 rad)"
    bad = Excess(math.inf, 1.0, "singular configuration", "tool on the pipe axis")
    assert bad.describe() == "singular configuration (tool on the pipe axis)" and bad.broken


def test_the_compiled_worst_is_the_largest_ratio_and_a_nan_first() -> None:
    floor = np.array([0.0, 0.0, 0.0, 0.0])
    tolerance = np.array([1e-4, 1e-3, 1e-6, 1.0])
    out = np.zeros(2)
    values = np.array([-1e-4, -5e-3, -2e-6, 0.5])  # ratios 1, 5, 2, -0.5
    assert worst_excess(values, floor, tolerance, out) == 1
    np.testing.assert_allclose(out, [5e-3, 5.0])
    values[2] = np.nan
    assert worst_excess(values, floor, tolerance, out) == 2
    assert np.isnan(out).all()
    assert worst_excess(np.zeros(0), np.zeros(0), np.zeros(0), out) == -1
    np.testing.assert_array_equal(out, [-np.inf, -np.inf])


class Shaky(VelocityDamper):
    """The probe's height, and a distance that is NaN where the tool's l is negative."""

    name = "shaky"
    quantity = "shake"

    def distances(self, state: KinematicState) -> Distances:
        value = np.array([state.tool[2], np.nan if state.tool[0] < 0 else 1.0])
        gradient = np.zeros((2, state.n))
        gradient[0] = state.tool_jacobian[2]
        return Distances(value, gradient, 0.0, lambda: ("shaky/height", "shaky/nan"))


def test_a_nan_excess_is_broken_and_the_worst(robot: Robot, q0: np.ndarray) -> None:
    nan = Excess(float("nan"), 1e-4, "a/nan")
    assert nan.broken
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    assert start.tool[0] > 0
    q = q0.copy()
    q[0] -= 2.0 * start.tool[0] / PIPE_RADIUS  # the carriage turns the tool to l < 0
    q[12] -= 0.3  # and the probe down, below its start: broken too, but not the worst
    height = SurfaceHeight(min_height=1.0)  # every point far below: broken by a lot
    s = stepping.stepper(robot, q0, limits=[height, Shaky()])
    assert not s.broken
    assert s.load(q) and s.broken
    found = s.excess()
    assert math.isnan(found.value) and found.broken
    assert found.quantity == "shake" and math.isnan(found.actual)  # the user damper's value
    assert math.isnan(s.excess_now[1])
