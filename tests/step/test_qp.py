"""The step's QP: written by the compiled step from the tasks, the objective and the limits.

``Stepper.prepare`` writes the problem in place; ``Stepper.problem()`` is the strict QP and
``Stepper.rows(limit)`` what one limit put in it.
"""

import re

import numpy as np
import pytest

from dvqp import (
    Bounds,
    Constraint,
    KinematicState,
    Limit,
    Obstacle,
    ObstacleSet,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    Task,
    TaskRows,
)
from dvqp.limits import JointPositionLimit, JointVelocityLimit, ObstacleDamper, SurfaceHeight
from dvqp.resolution.spec import DEFAULT_TASK_WEIGHT
from tests.common import PIPE_RADIUS, Q0, random_configurations, spec_with

DT = 0.005
COMMAND = np.array([0.01, 0.0, 0.0, 0.1])
FIELDS = ("P", "q", "A", "b", "G", "h", "lb", "ub")


def near_obstacles(robot: Robot) -> ObstacleSet:
    """One circle 2 cm from point 3, one over link 4's middle, one far away."""
    p = KinematicState.compute(robot, Q0, PIPE_RADIUS).points[:, :2]
    mid = 0.5 * (p[3] + p[4])
    return ObstacleSet(
        [
            Obstacle(p[2] + np.array([0.0, 0.05]), 0.03),
            Obstacle(mid + np.array([0.0, 0.045]), 0.03),
            Obstacle(np.array([-0.5, -1.0]), 0.05),
        ]
    )


def paper_limits(robot: Robot) -> tuple[Limit, ...]:
    return (
        JointPositionLimit(robot),
        JointVelocityLimit(robot),
        ObstacleDamper(near_obstacles(robot)),
        SurfaceHeight(min_height=0.075),
    )


def qp(robot: Robot, spec: StepSpec) -> Stepper:
    """The QP's compiled step of ``spec`` (DAQP), started at the paper's configuration."""
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), Q0, DT)
    s.start(Q0)
    return s


def problem_at(s: Stepper, q: np.ndarray) -> dict[str, np.ndarray | None]:
    assert s.load(q)
    assert s.prepare(COMMAND, DT) == -1
    p = s.problem()
    return {name: None if getattr(p, name) is None else getattr(p, name).copy() for name in FIELDS}


def test_the_problem_depends_on_the_state_only_and_has_the_documented_shape(robot: Robot) -> None:
    g = np.linspace(-1, 1, 13)
    w = np.linspace(0.5, 2.0, 13)
    s = qp(robot, spec_with(g, w, paper_limits(robot)))
    a, b = random_configurations(2, seed=1, spread=0.05)
    first = problem_at(s, a)
    problem_at(s, b)
    again = problem_at(s, a)  # nothing of the state at b is left over
    for name in FIELDS:
        np.testing.assert_array_equal(first[name], again[name], err_msg=name)
    p = s.problem()
    assert p.n == 13 and p.n_eq == 4
    np.testing.assert_array_equal(p.P, np.diag(w))
    np.testing.assert_array_equal(p.q, -g)  # λ = 1
    np.testing.assert_array_equal(p.A, KinematicState.compute(robot, a, PIPE_RADIUS).tool_jacobian)
    np.testing.assert_array_equal(p.b, COMMAND)
    relaxed = s.solver.relaxed  # type: ignore[union-attr]
    assert relaxed.n == 17 and relaxed.n_eq == 4
    np.testing.assert_array_equal(relaxed.A[:, 13:], -np.eye(4))
    np.testing.assert_array_equal(relaxed.P[13:, 13:], DEFAULT_TASK_WEIGHT * np.eye(4))
    assert np.isinf(relaxed.lb[13:]).all() and np.isinf(relaxed.ub[13:]).all()


def test_rows_come_in_the_order_of_the_limits(robot: Robot) -> None:
    limits = paper_limits(robot)
    s = qp(robot, spec_with(np.zeros(13), limits=limits))
    s.prepare(COMMAND, DT)
    p = s.problem()
    damper, height = s.rows(limits[2]), s.rows(limits[3])
    assert isinstance(damper, Constraint) and isinstance(height, Constraint)
    assert damper.rows > 0 and height.rows >= robot.n_points  # the floor is 5 mm below
    applies = np.isfinite(p.h)
    np.testing.assert_array_equal(p.G[applies], np.vstack([damper.G, height.G]))
    np.testing.assert_array_equal(p.h[applies], np.concatenate([damper.h, height.h]))
    assert not p.G[~applies].any()  # a row that does not apply: 0 · Q̇ ≤ +inf
    assert all("/obstacle" in label for label in damper.labels)
    points = tuple(f"point{i + 1}/height" for i in range(robot.n_points))
    assert height.labels[: robot.n_points] == points  # then the link chords that dip lowest
    chords = height.labels[robot.n_points :]
    assert all(re.fullmatch(r"(link[1-4]|carriage)/height", x) for x in chords)
    # the box is the position box intersected with the velocity box, each on its own
    alone = [qp(robot, spec_with(np.zeros(13), limits=(limit,))) for limit in limits[:2]]
    for other in alone:
        other.prepare(COMMAND, DT)
    position, velocity = (other.rows(limit) for other, limit in zip(alone, limits[:2], strict=True))
    box = s.rows(limits[0])
    assert isinstance(box, Bounds) and isinstance(position, Bounds)
    assert isinstance(velocity, Bounds)
    np.testing.assert_array_equal(box.lb, np.maximum(position.lb, velocity.lb))
    np.testing.assert_array_equal(box.ub, np.minimum(position.ub, velocity.ub))
    np.testing.assert_array_equal(velocity.ub, robot.qd_max)
    np.testing.assert_array_equal(position.ub[1:], (robot.q_max - Q0)[1:] / DT)


def test_without_limits_there_are_no_rows_and_no_box(robot: Robot) -> None:
    s = qp(robot, spec_with(np.zeros(13)))
    s.prepare(COMMAND, DT)
    p = s.problem()
    assert p.G is None and p.h is None
    assert np.all(np.isinf(p.lb)) and np.all(np.isinf(p.ub))


class Keep(Limit):
    """A user limit returning a fixed constraint or box."""

    name = "keep"

    def __init__(self, rows: Constraint | Bounds) -> None:
        self.fixed = rows

    def compute(self, state, dt):  # type: ignore[no-untyped-def]
        return self.fixed


class Track(Task):
    """A soft task ``q̇_0 ≈ 0.3`` with weight 2."""

    name = "track"
    hard = False

    def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
        row = np.zeros((1, state.n))
        row[0, 0] = 1.0
        return TaskRows(row, np.array([0.3]), 2.0)


def test_user_limits_and_soft_tasks_enter_the_problem(robot: Robot) -> None:
    G = np.zeros((1, 13))
    G[0, 2] = 1.0
    box = Bounds(np.full(13, -0.2), np.full(13, 0.2))
    constraint = Keep(Constraint(G, np.array([0.1])))
    spec = spec_with(np.ones(13), limits=(constraint, Keep(box))).with_extra(tasks=[Track()])
    s = qp(robot, spec)
    for _ in range(2):  # the soft cost is written afresh at every step, not added up
        s.load(Q0)
        s.prepare(COMMAND, DT)
    p = s.problem()
    np.testing.assert_array_equal(p.G, G)
    np.testing.assert_array_equal(p.h, [0.1])
    np.testing.assert_array_equal(p.ub, box.ub)
    np.testing.assert_array_equal(p.lb, box.lb)
    expected_P = np.eye(13)
    expected_P[0, 0] += 2.0
    np.testing.assert_array_equal(p.P, expected_P)
    expected_q = -np.ones(13)
    expected_q[0] -= 2.0 * 0.3
    np.testing.assert_allclose(p.q, expected_q)
    rows = s.rows(constraint)
    assert isinstance(rows, Constraint)
    np.testing.assert_array_equal(rows.G, G)


def test_two_hard_tasks_stack_into_one_equality(robot: Robot) -> None:
    class Freeze(Task):
        name = "freeze"

        def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
            return TaskRows(np.eye(1, state.n, 7), np.zeros(1))

    s = qp(robot, spec_with(np.zeros(13)).with_extra(tasks=[Freeze()]))
    s.prepare(COMMAND, DT)
    p = s.problem()
    assert p.n_eq == 5 and s.solver.relaxed.n == 18  # type: ignore[union-attr]
    np.testing.assert_array_equal(p.A[4], np.eye(1, 13, 7)[0])
    np.testing.assert_array_equal(p.b, [*COMMAND, 0.0])
    s.x[:] = 0.0
    s.move()  # the task error of Q̇ = 0 is the largest command
    assert s.motion[0] == pytest.approx(0.1)
    found = s.resolve(COMMAND, DT)
    assert found.status == "optimal" and abs(s.x[7]) < 1e-12
