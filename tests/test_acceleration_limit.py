"""Joint acceleration limits: the box around the last velocity and the braking bound."""

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import AccelerationLimit
from tests.common import LINK_LENGTHS, PIPE_RADIUS

DT = 0.01


def test_the_box_is_the_last_velocity_plus_or_minus_qdd_dt(robot: Robot, q0: np.ndarray) -> None:
    limit = AccelerationLimit(robot, 5.0)
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    box = limit.compute(state, DT)
    np.testing.assert_allclose(box.lb, -0.05)  # at rest: ±5 rad/s² · 0.01 s
    np.testing.assert_allclose(box.ub, 0.05)
    limit.observe(np.linspace(-1, 1, 13), DT)
    box = limit.compute(state, DT)
    np.testing.assert_allclose(box.ub - box.lb, 0.1)
    np.testing.assert_allclose(0.5 * (box.ub + box.lb), np.linspace(-1, 1, 13))
    limit.reset()
    np.testing.assert_array_equal(limit.previous, 0.0)


def test_a_joint_driven_at_its_limit_brakes_in_time_within_qdd(q0: np.ndarray) -> None:
    """Push joint 3 toward q_max as fast as allowed: it stops at the limit, never past it,
    and never changes speed faster than q̈_max."""
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5, qd_max=2.0)
    a = 4.0
    limit = AccelerationLimit(robot, a)
    q = np.clip(q0, -0.45, 0.45)
    q[2] = -0.4
    speeds = []
    for _ in range(400):
        box = limit.compute(KinematicState.compute(robot, q, PIPE_RADIUS), DT)
        v = np.clip(np.full(13, 0.0), box.lb, box.ub)
        v[2] = min(box.ub[2], robot.qd_max[2])  # as fast as the bounds let it
        speeds.append(v[2])
        limit.observe(v, DT)
        q = q + DT * v
        assert q[2] <= 0.5 + 1e-12
    speeds_arr = np.array(speeds)
    assert np.abs(np.diff(np.concatenate([[0.0], speeds_arr]))).max() <= a * DT + 1e-12
    assert (
        q[2] == pytest.approx(0.5, abs=2e-3) and speeds_arr.max() > 1.0
    )  # got going, then stopped


def test_the_braking_bound_is_the_fastest_speed_that_still_stops_in_time(
    robot: Robot, q0: np.ndarray
) -> None:
    limited = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    limit = AccelerationLimit(limited, 4.0)
    q = np.clip(q0, -0.45, 0.45)
    q[5] = 0.5 - 0.02  # 2 cm of room
    limit.observe(np.full(13, 3.0), DT)  # coming fast
    ub = limit.compute(KinematicState.compute(limited, q, PIPE_RADIUS), DT).ub[5]
    assert ub * DT + ub**2 / (2 * 4.0) == pytest.approx(0.02, rel=1e-12)


def test_constructor_validates_the_limit(robot: Robot) -> None:
    with pytest.raises(ParameterError, match="qdd_max"):
        AccelerationLimit(robot, 0.0)
