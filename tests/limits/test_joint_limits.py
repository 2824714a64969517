"""Joint position limits one step ahead, joint velocity limits, and the box they make."""

import numpy as np

from dvqp import Bounds, Robot
from dvqp.limits import AccelerationLimit, JointPositionLimit, JointVelocityLimit
from tests import stepping
from tests.common import LINK_LENGTHS
from tests.limit_fixtures import DT, DTS, configurations
from tests.oracles.limits import joint_box


def box(limit: object, robot: Robot, q: np.ndarray, dt: float = DT) -> Bounds:
    found = stepping.rows(limit, robot, q, dt)  # type: ignore[arg-type]
    assert isinstance(found, Bounds)
    return found


def test_position_bounds_stop_exactly_at_the_limit(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    found = box(JointPositionLimit(robot), robot, q)
    np.testing.assert_allclose(q + DT * found.ub, 0.5)
    np.testing.assert_allclose(q + DT * found.lb, -0.5)


def test_a_joint_past_its_limit_may_not_move_further_out(q0: np.ndarray) -> None:
    robot = Robot.ndt13(LINK_LENGTHS, q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    q[3] = 0.6
    q[7] = -0.7
    found = box(JointPositionLimit(robot), robot, q)
    assert found.ub[3] == 0.0 and found.lb[3] < 0.0
    assert found.lb[7] == 0.0 and found.ub[7] > 0.0


def test_velocity_bounds_are_the_robot_limits(robot: Robot, q0: np.ndarray) -> None:
    found = box(JointVelocityLimit(robot), robot, q0)
    np.testing.assert_array_equal(found.ub, robot.qd_max)
    np.testing.assert_array_equal(found.lb, -robot.qd_max)


def test_an_unlimited_joint_has_an_open_box(robot: Robot, q0: np.ndarray) -> None:
    found = box(JointPositionLimit(robot), robot, q0)  # joint 1 (the carriage) is unlimited
    assert found.lb[0] == -np.inf and found.ub[0] == np.inf
    assert np.isfinite(found.lb[1:]).all() and np.isfinite(found.ub[1:]).all()


def test_the_joint_limits_intersect_into_one_box(q0: np.ndarray) -> None:
    """Position limits of two robots (finite, infinite, and joints past them), velocity
    limits and the acceleration box: one box, their intersection, at every step."""
    q_min, q_max = q0 - 0.1, q0 + 0.1
    q_min[0], q_max[3] = -np.inf, np.inf
    limited = Robot.ndt13(LINK_LENGTHS, q_min=q_min, q_max=q_max, qd_max=np.linspace(0.5, 3.0, 13))
    tighter = Robot.ndt13(LINK_LENGTHS, q_min=q0 - 0.15, q_max=q0 + 0.05, qd_max=2.0)
    acceleration = AccelerationLimit(limited, np.linspace(2.0, 12.0, 13))
    limits = (
        JointPositionLimit(limited),
        JointVelocityLimit(limited),
        JointPositionLimit(tighter),
        JointVelocityLimit(tighter),
        acceleration,
    )
    s = stepping.stepper(limited, q0, limits=limits, backend="daqp")
    rng = np.random.default_rng(3)
    past = 0
    for q in configurations(limited, q0, 8, seed=4, spread=0.2):
        past += int(np.sum((q > q_max) | (q < q_min)))
        for dt in DTS:
            acceleration.observe(rng.uniform(-1.0, 1.0, 13), dt)
            assert s.load(q)
            status = s.prepare(np.zeros(4), dt)
            lb, ub = joint_box(limits, q, dt)
            crossed = np.flatnonzero(lb > ub)
            assert status == (crossed[0] if crossed.size else -1)
            for limit in limits:  # each reports the box of all
                found = s.rows(limit)
                assert isinstance(found, Bounds)
                np.testing.assert_array_equal(found.lb, lb)
                np.testing.assert_array_equal(found.ub, ub)
            if not crossed.size:
                problem = s.problem()
                np.testing.assert_array_equal(problem.lb, lb)
                np.testing.assert_array_equal(problem.ub, ub)
    assert past > 10  # many joints started past their limits


def test_crossed_bounds_name_the_first_joint_and_fail_the_step(q0: np.ndarray) -> None:
    """Still moving at 3 rad/s where the velocity limit is 1 rad/s: the acceleration box
    misses the velocity box; the step fails naming the first such joint."""
    robot = Robot.ndt13(LINK_LENGTHS, qd_max=1.0)
    acceleration = AccelerationLimit(robot, 10.0)
    limits = [JointVelocityLimit(robot), acceleration]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    previous = np.zeros(13)
    previous[[4, 9]] = 3.0
    s.observe(previous, DT)
    np.testing.assert_array_equal(acceleration.previous, previous)
    assert s.prepare(np.zeros(4), DT) == 4
    found = s.resolve(np.zeros(4), DT)
    assert not found.success and "joint5" in found.status
