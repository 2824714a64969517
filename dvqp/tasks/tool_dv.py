"""The operator's task: the tool's developed-view velocity (paper eq. 9), or some of it."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.tasks.task import (
    Deviation,
    Samples,
    Task,
    TaskRows,
    check_components,
    check_priority,
    check_weight,
)
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit

COMPONENTS = ("l", "z", "h", "alpha")
"""The tool's developed-view coordinates, in the order of ``J̄``'s rows."""
UNITS = ("m", "m", "m", "rad")


class ToolTask(Task):
    """``J̄_c(Q) Q̇ = ẋ_c``: the tool moves at the commanded DV velocity ``[l̇, ż, ḣ, α̇]``, in
    the ``components`` chosen (default all four).

    A hard task (compiled, :func:`tool_rows`): the QP's equality at its ``priority``, given way
    with a slack only where the limits (or a level above) forbid it. Split the tool over two
    priorities (``ToolTask(("h", "alpha"))`` above ``ToolTask(("l", "z"), priority=2)``) to keep
    the probe's height and heading when its reach along the weld runs out.

    Parameters
    ----------
    components
        A non-empty subset of ``("l", "z", "h", "alpha")``.
    priority
        Integer >= 1, 1 the highest.
    weight
        > 0: the rows' weight within their level when it gives way.

    Raises
    ------
    ParameterError
        An empty, unknown or repeated component; a priority that is not an integer >= 1; a
        weight not > 0.
    """

    name = "tool"
    hard = True

    def __init__(
        self, components: Sequence[str] = COMPONENTS, *, priority: int = 1, weight: float = 1.0
    ) -> None:
        self.components = check_components("components", components, COMPONENTS)
        self.priority = check_priority(priority)
        self.weight = check_weight(weight)

    def __repr__(self) -> str:
        given = [] if self.components == COMPONENTS else [repr(self.components)]
        given += [] if self.priority == 1 else [f"priority={self.priority}"]
        given += [] if self.weight == 1.0 else [f"weight={self.weight:g}"]
        return f"ToolTask({', '.join(given)})"

    @property
    def label(self) -> str:
        """``"tool"``, or ``"tool h, alpha"`` for some of its components."""
        parts = "" if self.components == COMPONENTS else " " + ", ".join(self.components)
        return f"tool{parts}"

    @property
    def follows(self) -> tuple[str, ...]:
        """Its components, as a hard task (a soft one only leans toward them)."""
        return self.components if self.hard else ()

    @property
    def index(self) -> NDArray[np.int64]:
        """The components' rows of ``J̄`` (0 l, 1 z, 2 h, 3 α), shape (m,)."""
        return np.array([COMPONENTS.index(c) for c in self.components], dtype=np.int64)

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The rows :func:`tool_rows` writes: ``J̄``'s chosen rows (m, n) and the command's
        (m,)."""
        index = self.index
        m = index.shape[0]
        jacobian, velocity = np.zeros((m, state.n)), np.zeros(m)
        tool_rows(state.tool_jacobian, np.asarray(command, float), index, jacobian, velocity, 0)
        return TaskRows(jacobian, velocity, describe=lambda: self.components)

    def deviation(self, samples: Samples) -> Deviation | None:
        """The tool's error against the commanded motion in its components (None without a
        commanded motion)."""
        if samples.tool_error.shape[0] != samples.q.shape[0]:
            return None
        index = self.index
        return Deviation(samples.tool_error[:, index], tuple(UNITS[i] for i in index))

    def join(self, step: StepWiring) -> None:
        """Rows of the hard tasks, written by :func:`tool_rows`: the entry
        ``[first row, count, c0 .. c3]`` (components' rows of ``J̄``, −1 unused)."""
        if overrides(self, ToolTask, "compute", "kernel") or not self.hard:
            return super().join(step)
        index = self.index
        start = step.plan.task_rows(index.shape[0])[0].start
        padded = np.full(4, -1, np.int64)
        padded[: index.shape[0]] = index
        step.tasks["tool"].append((start, index.shape[0], *padded))
        return None


@njit(separate=True)
def tool_rows(
    tool_jacobian: NDArray[np.float64],
    command: NDArray[np.float64],
    components: NDArray[np.int64],
    A: NDArray[np.float64],
    b: NDArray[np.float64],
    start: int,
) -> None:
    """Rows ``start ..`` of ``A``, ``b``: ``J̄``'s rows ``components`` (of (4, n)) and the
    command's (of (4,))."""
    for i in range(components.shape[0]):
        c = components[i]
        b[start + i] = command[c]
        for j in range(A.shape[1]):
            A[start + i, j] = tool_jacobian[c, j]
