"""A task asks ``J Q̇ ≈ v`` of the joint velocities: hard (an equality) or soft (a cost).

A hard task is an equality of the QP; when the equality conflicts with the limits, the
relaxed problem gives it a slack with the large weight ``ρ`` and the step reports its task
error. A soft task adds ``½ Σ_i w_i (J_i Q̇ − v_i)²`` to the QP's cost, as pink's tasks do.
dvqp's own task (:class:`~dvqp.tasks.ToolTask`) is compiled; a task of your own derives from
:class:`Task` and implements :meth:`Task.compute` in NumPy.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.workspace import Kernel, StepPlan
from dvqp.workspace.wiring import StepWiring


@dataclass(frozen=True)
class TaskRows:
    """The rows ``J Q̇ ≈ v`` of a task at one state.

    Attributes
    ----------
    jacobian : ndarray, shape (m, n)
        ``J`` (task units per rad).
    velocity : ndarray, shape (m,)
        ``v``, the task velocity wanted this step (task units per s).
    weight : float or ndarray of shape (m,)
        ``w_i`` of a soft task's cost (ignored for a hard task).
    describe : callable, optional
        One label per row.
    """

    jacobian: NDArray[np.float64]
    velocity: NDArray[np.float64]
    weight: float | NDArray[np.float64] = 1.0
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)

    @property
    def rows(self) -> int:
        """Number of rows m."""
        return int(self.velocity.shape[0])

    def objective(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The soft cost ``½ Q̇ᵀ H Q̇ + cᵀ Q̇`` as ``(H, c)``: ``H = Jᵀ W J``, ``c = −Jᵀ W v``."""
        weighted = self.jacobian.T * self.weight  # (n, m)
        return weighted @ self.jacobian, -(weighted @ self.velocity)


class Task:
    """What the joint velocities should do this step.

    Attributes
    ----------
    name : str
        A label for reports.
    hard : bool
        True: an equality (relaxed only if it conflicts with the limits); False: a cost.
    """

    name: str = "task"
    hard: bool = True

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The task's rows at ``state``: implement it for a task of your own.

        Parameters
        ----------
        state
            Kinematics of this step (read-only).
        command
            The operator's tool command ``[l̇, ż, ḣ, α̇]`` this step (m/s, m/s, m/s, rad/s),
            shape (4,); a task that does not follow the operator ignores it.
        dt
            Step, s.
        """
        raise NotImplementedError(f"{type(self).__name__} has no compute(state, command, dt)")

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """Optionally, a hard task's rows as a compiled kernel (a soft task's cost is always
        its :meth:`compute`'s): ask ``plan`` for rows once
        (``A, b = plan.task_rows(m)``) and return a :class:`~dvqp.workspace.Kernel` writing
        ``J`` and ``v`` from ``plan.state``, ``plan.command`` and ``plan.dt`` at every step.
        None (the default): :meth:`compute` is used."""
        return None

    @property
    def measured(self) -> Sequence[Any]:
        """The obstacles whose distances the step must measure for this task (none)."""
        return ()

    def join(self, step: StepWiring) -> None:
        """Join the run's step: a task of your own through the run's hooks (its
        :meth:`kernel`, else :meth:`compute`); dvqp's own tasks write their rows in the
        compiled step instead."""
        step.hooks.task(self)
