"""The step's QP: built by a pure function from tasks, objective and limits."""

import numpy as np
import pytest

from dvqp import Bounds, Constraint, KinematicState, Robot, TaskRows, build_qp
from dvqp.limits import JointPositionLimit, JointVelocityLimit, ObstacleDamper, SurfaceHeight
from dvqp.resolution import limit_rows, step_terms
from tests.common import spec_with
from tests.limit_fixtures import DT, near_obstacles

COMMAND = np.array([0.01, 0.0, 0.0, 0.1])


def paper_limits(robot: Robot, state: KinematicState) -> tuple:  # type: ignore[type-arg]
    return (
        JointPositionLimit(robot),
        JointVelocityLimit(robot),
        ObstacleDamper(near_obstacles(state)),
        SurfaceHeight(min_height=0.02),
    )


def test_build_is_pure_and_has_the_documented_shape(robot: Robot, state0: KinematicState) -> None:
    g = np.linspace(-1, 1, 13)
    spec = spec_with(g, limits=paper_limits(robot, state0))
    a = build_qp(spec, state0, COMMAND, DT)
    b = build_qp(spec, state0, COMMAND, DT)
    for name in ("P", "q", "A", "b", "G", "h", "lb", "ub"):
        np.testing.assert_array_equal(getattr(a.problem, name), getattr(b.problem, name))
    assert a.problem.n == 13 and a.problem.n_eq == 4
    np.testing.assert_array_equal(a.problem.q, -g)
    np.testing.assert_array_equal(a.problem.A, state0.tool_jacobian)
    np.testing.assert_array_equal(a.problem.b, COMMAND)
    relaxed = build_qp(spec, state0, COMMAND, DT, relax=True)
    assert relaxed.problem.n == 17 and relaxed.relaxed
    np.testing.assert_array_equal(relaxed.problem.A[:, 13:], -np.eye(4))
    np.testing.assert_array_equal(relaxed.problem.P[13:, 13:], 1e4 * np.eye(4))


def test_rows_come_in_the_order_of_the_limits(robot: Robot, state0: KinematicState) -> None:
    limits = paper_limits(robot, state0)
    spec = spec_with(np.zeros(13), limits=limits)
    ineq, box = limit_rows(spec, state0, DT)
    damper, height = limits[2].compute(state0, DT), limits[3].compute(state0, DT)
    np.testing.assert_array_equal(ineq.G, np.vstack([damper.G, height.G]))
    assert ineq.labels == damper.labels + height.labels
    position, velocity = limits[0].compute(state0, DT), limits[1].compute(state0, DT)
    np.testing.assert_array_equal(box.lb, np.maximum(position.lb, velocity.lb))
    np.testing.assert_array_equal(box.ub, np.minimum(position.ub, velocity.ub))


def test_without_limits_there_are_no_rows_and_no_box(state0: KinematicState) -> None:
    qp = build_qp(spec_with(np.zeros(13)), state0, COMMAND, DT)
    assert qp.problem.G is None and qp.inequalities.rows == 0
    assert np.all(np.isinf(qp.problem.lb)) and np.all(np.isinf(qp.problem.ub))


class Keep:
    """A user limit returning a fixed constraint or box."""

    name = "keep"

    def __init__(self, rows: Constraint | Bounds) -> None:
        self.rows = rows

    def compute(self, state: KinematicState, dt: float) -> Constraint | Bounds:
        return self.rows


class Track:
    """A soft task ``q̇_0 ≈ 0.3`` with weight 2."""

    name = "track"
    hard = False

    def compute(self, state: KinematicState, command: np.ndarray, dt: float) -> TaskRows:
        row = np.zeros((1, state.n))
        row[0, 0] = 1.0
        return TaskRows(row, np.array([0.3]), 2.0)


def test_user_limits_and_soft_tasks_enter_the_problem(state0: KinematicState) -> None:
    G = np.zeros((1, 13))
    G[0, 2] = 1.0
    box = Bounds(np.full(13, -0.2), np.full(13, 0.2))
    spec = spec_with(np.ones(13), limits=(Keep(Constraint(G, np.array([0.1]))), Keep(box)))
    spec = spec.with_extra(tasks=[Track()])
    qp = build_qp(spec, state0, COMMAND, DT)
    np.testing.assert_array_equal(qp.problem.G, G)
    np.testing.assert_array_equal(qp.problem.ub, box.ub)
    expected_P = np.eye(13)
    expected_P[0, 0] += 2.0
    np.testing.assert_array_equal(qp.problem.P, expected_P)
    expected_q = -np.ones(13)
    expected_q[0] -= 2.0 * 0.3
    np.testing.assert_allclose(qp.problem.q, expected_q)
    assert step_terms(spec, state0, COMMAND, DT).soft_hessian is not None


def test_two_hard_tasks_stack_into_one_equality(state0: KinematicState) -> None:
    class Freeze:
        name, hard = "freeze", True

        def compute(self, state: KinematicState, command: np.ndarray, dt: float) -> TaskRows:
            return TaskRows(np.eye(1, state.n, 7), np.zeros(1))

    spec = spec_with(np.zeros(13)).with_extra(tasks=[Freeze()])
    qp = build_qp(spec, state0, COMMAND, DT, relax=True)
    assert qp.problem.n_eq == 5 and qp.problem.n == 18
    assert qp.terms.task_error(np.zeros(13)) == pytest.approx(0.1)
