"""Hold the joints at a posture (pink's PostureTask, at a priority)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.kinematics.state import KinematicState
from dvqp.tasks.task import (
    DEFAULT_GAIN,
    Deviation,
    Samples,
    Task,
    TaskRows,
    check_priority,
    check_weight,
)
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class PostureTask(Task):
    """``Q̇ = K (q* − q)``: every joint moves toward its target ``q*``.

    n rows (the identity): below other levels it takes whatever freedom they leave (pink's
    posture task as a regularisation), and as the lowest level it leaves none to ``∇w``. A hard
    task, compiled (:func:`posture_rows`), at its ``priority``.

    Parameters
    ----------
    target
        ``q*``, rad, shape (n,). None: the run's start configuration.
    gain
        ``K``, 1/s, >= 0.
    priority, weight
        As every task's (:class:`~dvqp.tasks.Task`).

    Raises
    ------
    ParameterError, ShapeError
        A target not finite (or, when the task joins a run, not of n numbers), a gain < 0, a
        priority not an integer >= 1, a weight not > 0.
    """

    name = "posture"
    hard = True

    def __init__(
        self,
        target: ArrayLike | None = None,
        *,
        gain: float = DEFAULT_GAIN,
        priority: int = 1,
        weight: float = 1.0,
    ) -> None:
        self.target = (
            None if target is None else _validate.readonly(_validate.vector("target", target))
        )
        self.gain = _validate.positive("gain", gain, strict=False)
        self.priority = check_priority(priority)
        self.weight = check_weight(weight)

    def __repr__(self) -> str:
        return f"PostureTask(priority={self.priority})"

    def goal(self, state: KinematicState) -> NDArray[np.float64]:
        """``q*``, or (None) the configuration of ``state``, rad, shape (n,)."""
        if self.target is None:
            return np.array(state.q)
        return _validate.vector("target", self.target, state.n)

    def compute(self, state: KinematicState, command: NDArray[np.float64], dt: float) -> TaskRows:
        """The rows :func:`posture_rows` writes toward :meth:`goal` at ``state`` (without a
        target: the joints held where they are)."""
        n = state.n
        jacobian, velocity = np.zeros((n, n)), np.zeros(n)
        posture_rows(state.q, self.goal(state), self.gain, jacobian, velocity, 0)
        return TaskRows(jacobian, velocity, describe=lambda: tuple(f"q{i + 1}" for i in range(n)))

    def deviation(self, samples: Samples) -> Deviation:
        """``q* − q`` at every sample, rad (without a target, against the first sample)."""
        goal = samples.q[0] if self.target is None else self.target
        return Deviation(goal[None, :] - samples.q, ("rad",) * samples.q.shape[1])

    def join(self, step: StepWiring) -> None:
        """n rows of the hard tasks, written by :func:`posture_rows`: the entry
        ``(first row, target (n,), gain)``."""
        if overrides(self, PostureTask, "compute", "kernel") or not self.hard:
            return super().join(step)
        goal = self.goal(step.start)
        step.tasks["posture"].append((step.plan.task_rows(step.plan.n)[0].start, goal, self.gain))
        return None


@njit(separate=True)
def posture_rows(
    q: NDArray[np.float64],
    target: NDArray[np.float64],
    gain: float,
    A: NDArray[np.float64],
    b: NDArray[np.float64],
    start: int,
) -> None:
    """Rows ``start .. start + n − 1`` of ``A``, ``b``: the identity and ``gain · (q* − q)``."""
    n = q.shape[0]
    for i in range(n):
        b[start + i] = gain * (target[i] - q[i])
        for j in range(A.shape[1]):
            A[start + i, j] = 1.0 if i == j else 0.0
