"""Exact verification of a configuration against the limits: the worst excess and its words."""

import math

import numpy as np
import pytest

from dvqp import KinematicState, Obstacle, ObstacleSet, Robot
from dvqp.geometry import proximity
from dvqp.limits import (
    Excess,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    SurfaceHeight,
    worst_excess,
)
from tests.common import LINK_LENGTHS, PIPE_RADIUS


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
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    worst = worst_excess([height, damper, JointVelocityLimit(robot)], start, moved)
    parts = [height.excess(start, moved), damper.excess(start, moved)]
    assert worst == max(parts, key=lambda e: e.ratio)


def test_a_clearance_below_the_start_is_broken_and_described(robot: Robot, q0: np.ndarray) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    q = q0.copy()
    q[12] += 0.3  # swing the probe
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    # a small circle where the probe ends, clear of the whole arm at the start
    obstacle = Obstacle(moved.tool[:2] + np.array([0.0, 0.002]), 0.004)
    damper = ObstacleDamper(ObstacleSet([obstacle]), margin=0.001)
    assert not damper.excess(start, start).broken
    found = damper.excess(start, moved)
    assert found.broken and found.label == "probe/obstacle1" and found.unit == "m"
    assert found.actual == pytest.approx(-0.002, abs=1e-9)
    start_clearance = proximity(start, damper.obstacles).point_clearance[0, -1]
    assert found.bound == pytest.approx(min(0.001, start_clearance))
    assert found.describe().startswith("probe/obstacle1 clearance -0.002 m < ")


def test_joint_excess_names_the_joint_and_allows_a_start_outside(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    q[4] = 0.6  # starts 0.1 rad out
    start = KinematicState.compute(robot, q, PIPE_RADIUS)
    limit = JointPositionLimit(robot)
    assert not limit.excess(start, start).broken
    q2 = q.copy()
    q2[4] = 0.61
    found = limit.excess(start, KinematicState.compute(robot, q2, PIPE_RADIUS))
    assert found.broken and found.label == "joint5"
    assert found.value == pytest.approx(0.01) and found.bound == pytest.approx(0.6)


def test_describe_reads_as_one_line() -> None:
    e = Excess(0.0038, 1e-4, "probe/obstacle3", "clearance", "m", 0.0062, 0.01)
    assert e.describe() == "probe/obstacle3 clearance 0.0062 m < 0.01 m (by 3.8 mm)"
    bad = Excess(math.inf, 1.0, "singular configuration", "tool on the pipe axis")
    assert bad.describe() == "singular configuration (tool on the pipe axis)" and bad.broken


def test_a_nan_excess_is_broken_and_the_worst() -> None:
    class Fixed:
        def __init__(self, excess: Excess) -> None:
            self.found = excess

        def excess(self, start: object, state: object) -> Excess:
            return self.found

    nan = Excess(float("nan"), 1e-4, "a/nan")
    assert nan.broken
    worst = worst_excess([Fixed(Excess(0.5, 1e-4, "big")), Fixed(nan)], None, None)  # type: ignore[arg-type]
    assert worst.label == "a/nan"
