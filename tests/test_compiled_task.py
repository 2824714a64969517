"""The tool task's compiled kernel: its rows of ``A, b`` hold ``J̄`` and the command."""

from __future__ import annotations

import numpy as np

from dvqp import KinematicState, ToolTask
from dvqp.compiled import StepPlan
from tests.common import PIPE_RADIUS


def test_the_tool_task_kernel_copies_the_tool_jacobian_and_command_into_its_rows(
    state0: KinematicState,
) -> None:
    plan = StepPlan(state0.n, state0.k, PIPE_RADIUS)
    plan.task_rows(2)  # rows of another task before the tool's
    kernel = plan.bind(ToolTask().kernel(plan))
    plan.state.load(state0)
    plan.command[:] = [0.05, -0.02, 0.0, 0.3]
    kernel.function(*kernel.args)
    A, b = plan.stacked["A"], plan.stacked["b"]
    assert A.shape == (6, state0.n) and b.shape == (6,)
    np.testing.assert_array_equal(A[2:], state0.tool_jacobian)
    np.testing.assert_array_equal(b[2:], [0.05, -0.02, 0.0, 0.3])
    assert not A[:2].any() and not b[:2].any()
    rows = ToolTask().compute(state0, plan.command, 0.005)
    np.testing.assert_array_equal(A[2:], rows.jacobian)
    plan.command[:] = 0.0  # the next step's command, read in place
    kernel.function(*kernel.args)
    assert not b.any()
