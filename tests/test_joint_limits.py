"""Joint position limits one step ahead, and joint velocity limits."""

import numpy as np

from dvqp import KinematicState, Robot
from dvqp.limits import JointPositionLimit, JointVelocityLimit
from tests.common import LINK_LENGTHS, PIPE_RADIUS
from tests.limit_fixtures import DT


def test_position_bounds_stop_exactly_at_the_limit(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    box = JointPositionLimit(robot).compute(state, DT)
    np.testing.assert_allclose(q + DT * box.ub, 0.5)
    np.testing.assert_allclose(q + DT * box.lb, -0.5)


def test_a_joint_past_its_limit_may_not_move_further_out(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    q[3] = 0.6
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    box = JointPositionLimit(robot).compute(state, DT)
    assert box.ub[3] == 0.0 and box.lb[3] < 0.0


def test_velocity_bounds_are_the_robot_limits(robot: Robot, state0: KinematicState) -> None:
    box = JointVelocityLimit(robot).compute(state0, DT)
    np.testing.assert_array_equal(box.ub, robot.qd_max)
    np.testing.assert_array_equal(box.lb, -robot.qd_max)
