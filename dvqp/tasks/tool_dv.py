"""The operator's task: the tool's developed-view velocity (paper eq. 9)."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.kinematics.state import KinematicState
from dvqp.tasks.task import TaskRows

_LABELS = ("tool/l", "tool/z", "tool/h", "tool/alpha")


class ToolTask:
    """``J̄(Q) Q̇ = ẋ``: the tool moves at the commanded DV velocity ``[l̇, ż, ḣ, α̇]``.

    A hard task: the QP's equality, relaxed with a slack only when the limits forbid it.
    """

    name = "tool"
    hard = True

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """``J̄`` (4, n) and the command (4,)."""
        return TaskRows(state.tool_jacobian, command, describe=lambda: _LABELS)

    def kernel(self, plan: StepPlan) -> Kernel:
        """Four rows of ``A, b``: a kernel copying ``J̄`` (``plan.state.tool_jacobian``) and
        the command (``plan.command``) into them each step."""
        A, b = plan.task_rows(4)
        return Kernel(_copy_rows, (plan.state.tool_jacobian, plan.command, A, b))

    def __repr__(self) -> str:
        return "ToolTask()"


@njit(cache=True)
def _copy_rows(jacobian: NDArray[np.float64], command: NDArray[np.float64],
               A: NDArray[np.float64], b: NDArray[np.float64]) -> None:  # fmt: skip
    """``A = jacobian`` (m, n), ``b = command`` (m,), in place."""
    for i in range(b.shape[0]):
        b[i] = command[i]
        for j in range(A.shape[1]):
            A[i, j] = jacobian[i, j]
