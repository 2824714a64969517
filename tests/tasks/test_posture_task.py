"""A posture task's rows are the identity and the velocity that closes the gap to its target
posture; the step writes exactly those rows."""

from __future__ import annotations

import numpy as np
import pytest

from dvqp import (
    KinematicState,
    Objective,
    PostureTask,
    QPResolver,
    Robot,
    ShapeError,
    Stepper,
    StepSpec,
    ToolTask,
)
from tests.common import PIPE_RADIUS, central_difference, random_configurations

DT = 0.005


def test_the_rows_are_the_joints_derivative_and_close_the_gap(robot: Robot) -> None:
    q, target = random_configurations(2, seed=3, spread=0.4)
    task = PostureTask(target, gain=2.5)

    def velocity(v: np.ndarray) -> np.ndarray:
        return task.compute(KinematicState.compute(robot, v, PIPE_RADIUS), np.zeros(4), DT).velocity

    rows = task.compute(KinematicState.compute(robot, q, PIPE_RADIUS), np.zeros(4), DT)
    # the rows are ∂q/∂q, and the velocity's derivative is −gain times them
    np.testing.assert_allclose(rows.jacobian, central_difference(lambda v: v, q, 1e-6), atol=1e-9)
    np.testing.assert_allclose(
        -central_difference(velocity, q, 1e-6) / 2.5, rows.jacobian, atol=1e-8
    )
    np.testing.assert_allclose(rows.velocity, 2.5 * (target - q), atol=1e-15)
    assert len(rows.describe()) == 13  # type: ignore[misc]


def test_the_step_writes_the_tasks_rows_toward_the_start(robot: Robot, q0: np.ndarray) -> None:
    spec = StepSpec((ToolTask(), PostureTask(priority=2, gain=4.0)), Objective())
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)
    s.start(q0)
    q = random_configurations(1, seed=5, spread=0.2)[0]
    assert s.load(q)
    s.prepare(np.zeros(4), DT)
    p = s.problem()
    np.testing.assert_array_equal(p.A[4:], np.eye(13))
    np.testing.assert_allclose(p.b[4:], 4.0 * (q0 - q), atol=1e-15)


def test_a_target_of_the_wrong_length_is_refused(robot: Robot, q0: np.ndarray) -> None:
    spec = StepSpec((ToolTask(), PostureTask(np.zeros(12), priority=2)), Objective())
    with pytest.raises(ShapeError, match="target"):
        Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)
