"""The tool task's rows of ``A, b`` hold ``J̄`` and the command, after a user's task's rows."""

from __future__ import annotations

import numpy as np

from dvqp import (
    KinematicState,
    Objective,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    Task,
    TaskRows,
    ToolTask,
)
from dvqp.kinematics.developed_view import wrap, wrap_angle
from tests.common import PIPE_RADIUS, central_difference

DT = 0.005


class Hold(Task):
    """A user's hard task of two rows: joints 2 and 3 at a given speed."""

    name = "hold"

    def compute(self, state: KinematicState, command: np.ndarray, dt: float) -> TaskRows:
        J = np.zeros((2, state.n))
        J[0, 1] = J[1, 2] = 1.0
        return TaskRows(J, np.array([0.01, -0.02]))


def test_the_tool_rows_are_the_tool_jacobian_and_the_command(robot: Robot, q0: np.ndarray) -> None:
    spec = StepSpec((Hold(), ToolTask()), Objective())
    s = Stepper(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), q0, DT)
    s.start(q0)
    command = np.array([0.05, -0.02, 0.0, 0.3])
    s.prepare(command, DT)
    problem = s.problem()
    assert problem.A.shape == (6, 13) and problem.b.shape == (6,)
    np.testing.assert_array_equal(problem.A[:2], Hold().compute(s.state, command, DT).jacobian)
    np.testing.assert_array_equal(problem.b[:2], [0.01, -0.02])
    np.testing.assert_array_equal(problem.A[2:], s.state.tool_jacobian)
    np.testing.assert_array_equal(problem.b[2:], command)

    def tool(v: np.ndarray) -> np.ndarray:
        return np.array(KinematicState.compute(robot, v, PIPE_RADIUS).tool)

    def wrapped(d: np.ndarray) -> np.ndarray:
        return np.r_[wrap(d[0], PIPE_RADIUS), d[1:3], wrap_angle(d[3])]

    fd = central_difference(tool, q0, 1e-7, wrap=wrapped)
    np.testing.assert_allclose(problem.A[2:], fd, rtol=1e-6, atol=1e-7)
    s.prepare(np.zeros(4), DT)  # the next step's command, read in place
    assert not s.problem().b[2:].any()
    q = q0 + 0.05
    assert s.load(q)
    s.prepare(command, DT)
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    np.testing.assert_array_equal(s.problem().A[2:], moved.tool_jacobian)
