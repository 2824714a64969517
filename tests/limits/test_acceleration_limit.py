"""Joint acceleration limits: the box around the last velocity and the braking bound."""

import numpy as np
import pytest

from dvqp import Bounds, Objective, QPResolver, Robot, Stepper, StepSpec, ToolTask
from dvqp.errors import ParameterError
from dvqp.limits import AccelerationLimit, JointPositionLimit
from tests import stepping
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.oracles.limits import acceleration_box, braking

DT = 0.01


def box(s: Stepper, limit: AccelerationLimit, q: np.ndarray, dt: float = DT) -> Bounds:
    assert s.load(q)
    s.prepare(np.zeros(4), dt)
    found = s.rows(limit)
    assert isinstance(found, Bounds)
    return found


def test_the_box_is_the_last_velocity_plus_or_minus_qdd_dt(robot: Robot, q0: np.ndarray) -> None:
    limit = AccelerationLimit(robot, 5.0)
    s = stepping.stepper(robot, q0, limits=[limit], backend="daqp")
    found = box(s, limit, q0)
    np.testing.assert_allclose(found.lb, -0.05)  # at rest: ±5 rad/s² · 0.01 s
    np.testing.assert_allclose(found.ub, 0.05)
    s.observe(np.linspace(-1, 1, 13), DT)
    found = box(s, limit, q0)
    np.testing.assert_allclose(found.ub - found.lb, 0.1)
    np.testing.assert_allclose(0.5 * (found.ub + found.lb), np.linspace(-1, 1, 13))
    s.start(q0)  # a new run starts at rest
    np.testing.assert_array_equal(limit.previous, 0.0)
    np.testing.assert_allclose(box(s, limit, q0).ub, 0.05)


def test_the_limit_keeps_one_live_previous_velocity(robot: Robot) -> None:
    limit = AccelerationLimit(robot)
    previous = limit.previous
    limit.observe(np.arange(13.0), 0.01)
    assert limit.previous is previous
    np.testing.assert_array_equal(previous, np.arange(13.0))
    limit.reset()
    assert limit.previous is previous and not previous.any()


def test_a_joint_driven_at_its_limit_brakes_in_time_within_qdd(q0: np.ndarray) -> None:
    """Push joint 3 toward q_max as fast as allowed: it stops at the limit, never past it,
    and never changes speed faster than q̈_max."""
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5, qd_max=2.0)
    a = 4.0
    limit = AccelerationLimit(robot, a)
    q = np.clip(q0, -0.45, 0.45)
    q[2] = -0.4
    s = stepping.stepper(robot, q, limits=[limit], backend="daqp", dt=DT)
    speeds = []
    for _ in range(400):
        found = box(s, limit, q)
        v = np.clip(np.full(13, 0.0), found.lb, found.ub)
        v[2] = min(found.ub[2], robot.qd_max[2])  # as fast as the bounds let it
        speeds.append(v[2])
        s.observe(v, DT)
        q = q + DT * v
        assert q[2] <= 0.5 + 1e-12
    speeds_arr = np.array(speeds)
    assert np.abs(np.diff(np.concatenate([[0.0], speeds_arr]))).max() <= a * DT + 1e-12
    assert (
        q[2] == pytest.approx(0.5, abs=2e-3) and speeds_arr.max() > 1.0
    )  # got going, then stopped


def test_the_braking_bound_is_the_fastest_speed_that_still_stops_in_time(
    q0: np.ndarray,
) -> None:
    limited = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    limit = AccelerationLimit(limited, 4.0)
    q = np.clip(q0, -0.45, 0.45)
    q[5] = 0.5 - 0.02  # 2 cm of room
    q[8] = -0.5 + 0.03  # 3 cm toward q_min
    s = stepping.stepper(limited, q, limits=[limit], backend="daqp", dt=DT)
    previous = np.zeros(13)
    previous[5], previous[8] = 3.0, -0.43  # coming fast, and not so fast
    s.observe(previous, DT)
    found = box(s, limit, q)
    ub, lb = found.ub[5], -found.lb[8]
    assert ub * DT + ub**2 / (2 * 4.0) == pytest.approx(0.02, rel=1e-12)
    assert lb * DT + lb**2 / (2 * 4.0) == pytest.approx(0.03, rel=1e-12)
    lb_all, ub_all = acceleration_box(limit, q, DT)
    np.testing.assert_array_equal(found.lb, lb_all)
    np.testing.assert_array_equal(found.ub, ub_all)


def test_a_joint_that_cannot_brake_in_time_keeps_its_position_limit(q0: np.ndarray) -> None:
    """Past the braking distance the acceleration box has nothing left: its lower bound
    falls to its upper one (no crossed box), the position limit holds the joint."""
    limited = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    limit = AccelerationLimit(limited, 2.0)
    q = np.clip(q0, -0.45, 0.45)
    q[4] = 0.5 - 1e-4  # 0.1 mrad of room at 3 rad/s
    previous = np.zeros(13)
    previous[4] = 3.0
    limit.observe(previous, DT)
    lb, ub = acceleration_box(limit, q, DT)
    assert lb[4] == ub[4] == braking(np.array(2.0), DT, 0.5 - q[4])
    spec = StepSpec((ToolTask(),), Objective(), (JointPositionLimit(limited), limit))
    s = Stepper(limited, PIPE_RADIUS, QPResolver(spec, "daqp"), q, DT)
    assert s.load(q)
    limit.observe(previous, DT)  # after start() reset it
    assert s.prepare(np.zeros(4), DT) == -1
    found = s.rows(limit)
    assert isinstance(found, Bounds)
    assert found.lb[4] == found.ub[4] == ub[4]


def test_one_acceleration_limit_per_step(robot: Robot) -> None:
    with pytest.raises(ParameterError, match="AccelerationLimit"):
        StepSpec((ToolTask(),), Objective(), (AccelerationLimit(robot), AccelerationLimit(robot)))


def test_constructor_validates_the_limit(robot: Robot) -> None:
    with pytest.raises(ParameterError, match="qdd_max"):
        AccelerationLimit(robot, 0.0)
    with pytest.raises(ParameterError, match="qdd_max"):
        AccelerationLimit(robot, np.r_[np.ones(12), -1.0])
