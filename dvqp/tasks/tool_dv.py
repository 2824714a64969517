"""The operator's task: the tool's developed-view velocity (paper eq. 9)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.tasks.task import Task, TaskRows
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class ToolTask(Task):
    """``J̄(Q) Q̇ = ẋ``: the tool moves at the commanded DV velocity ``[l̇, ż, ḣ, α̇]``.

    A hard task (compiled, :func:`tool_rows`): the QP's equality, relaxed with a slack only
    when the limits forbid it.
    """

    name = "tool"
    hard = True

    def __repr__(self) -> str:
        return "ToolTask()"

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The rows :func:`tool_rows` writes: ``J̄`` (4, n) and the command (4,)."""
        jacobian, velocity = np.zeros((4, state.n)), np.zeros(4)
        tool_rows(state.tool_jacobian, np.asarray(command, float), jacobian, velocity, 0)
        return TaskRows(jacobian, velocity, describe=lambda: ("l", "z", "h", "alpha"))

    def join(self, step: StepWiring) -> None:
        """Four rows of the hard tasks, written by :func:`tool_rows`."""
        if overrides(self, ToolTask, "compute", "kernel") or not self.hard:
            return super().join(step)
        step.measures["tool_rows"].append(step.plan.task_rows(4)[0].start)
        return None


@njit(separate=True)
def tool_rows(
    tool_jacobian: NDArray[np.float64],
    command: NDArray[np.float64],
    A: NDArray[np.float64],
    b: NDArray[np.float64],
    start: int,
) -> None:
    """Rows ``start .. start + 3`` of ``A``, ``b``: ``J̄`` (4, n) and the command (4,)."""
    for i in range(4):
        b[start + i] = command[i]
        for j in range(A.shape[1]):
            A[start + i, j] = tool_jacobian[i, j]
