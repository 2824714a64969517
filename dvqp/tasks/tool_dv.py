"""The operator's task: the tool's developed-view velocity (paper eq. 9)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

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

    def __repr__(self) -> str:
        return "ToolTask()"
