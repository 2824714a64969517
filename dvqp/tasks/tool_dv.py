"""The operator's task: the tool's developed-view velocity (paper eq. 9)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.tasks.task import Task
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


@njit
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
