"""A task asks ``J Q̇ ≈ v`` of the joint velocities: hard (an equality) or soft (a cost).

A hard task is an equality of the QP at its ``priority`` (1 the highest): tasks of one priority
form a level, and each level is met as well as the limits and the levels above let it
(:mod:`dvqp.resolution.levels`); a level the limits forbid gives way with a slack weighted
``ρ · weight`` per row and the step reports its task error. A soft task adds
``½ Σ_i w_i (J_i Q̇ − v_i)²`` to the QP's cost, as pink's tasks do: it sits with ``∇w`` below
every level. dvqp's own tasks (:class:`~dvqp.tasks.ToolTask`, :class:`~dvqp.tasks.PointTask`,
:class:`~dvqp.tasks.PostureTask`) are compiled; :class:`~dvqp.tasks.FrameTask` and a task of
your own derive from :class:`Task` and implement :meth:`Task.compute` in NumPy.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import Kernel, StepPlan
from dvqp.workspace.wiring import StepWiring

DEFAULT_GAIN = 5.0
"""1/s: how fast a task that holds a target (a point, a posture, a frame) closes its error,
``v = gain · (target − value)``; the path follower's default feedback gain."""


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


@dataclass(frozen=True)
class Samples:
    """What a run recorded, for a task to measure its own error at every sample
    (:meth:`Task.deviation`): ``q`` (N+1, n) rad, the tool's ``tool_error`` against the
    commanded motion (N+1, 4) (m, m, m, rad; (0, 4) if there was none), the body points
    ``points`` (N+1, k, 3) m, the pipe's ``radius`` m."""

    q: NDArray[np.float64]
    tool_error: NDArray[np.float64]
    points: NDArray[np.float64]
    radius: float


@dataclass(frozen=True)
class Deviation:
    """A task's error at every sample of a run: ``values`` (N+1, m), each row's ``units``
    (``"m"`` or ``"rad"``), m long."""

    values: NDArray[np.float64]
    units: tuple[str, ...]


class Task:
    """What the joint velocities should do this step.

    Attributes
    ----------
    name : str
        A label for reports.
    hard : bool
        True: an equality at its ``priority`` (given way only where the limits or a level
        above forbid it); False: a cost, with ``∇w``, below every level.
    priority : int
        1 the highest; hard tasks of one priority form one level, strictly below the levels of
        smaller priorities (a lower level moves only in what the levels above leave free).
    weight : float
        > 0: how much a row of this task counts against the others of its level when the level
        gives way (its slack's weight is ``ρ · weight``).
    """

    name: str = "task"
    hard: bool = True
    priority: int = 1
    weight: float = 1.0

    @property
    def label(self) -> str:
        """What reports call it (``"tool h, alpha"``): its name by default."""
        return self.name

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
    def follows(self) -> tuple[str, ...]:
        """The components of the operator's tool command (``"l"``, ``"z"``, ``"h"``,
        ``"alpha"``) this task makes the tool follow: none by default (a scene whose motion
        commands a component no task follows is refused at load)."""
        return ()

    @property
    def measured(self) -> Sequence[Any]:
        """The obstacles whose distances the step must measure for this task (none)."""
        return ()

    def deviation(self, samples: Samples) -> Deviation | None:
        """The task's error at every sample of a run (position units: m, rad), for reports;
        None (the default): it does not say (its level is reported by its residual alone)."""
        return None

    def join(self, step: StepWiring) -> None:
        """Join the run's step: a task of your own through the run's hooks (its
        :meth:`kernel`, else :meth:`compute`); dvqp's own tasks write their rows in the
        compiled step instead."""
        step.hooks.task(self)


def check_priority(value: object, name: str = "priority") -> int:
    """``value`` as a priority: an integer >= 1 (not a bool, not a float).

    Raises
    ------
    ParameterError
        Anything else.
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ParameterError(name, f"must be an integer >= 1 (1 the highest), got {value!r}")
    return int(value)


def check_components(name: str, given: Sequence[str], known: Sequence[str]) -> tuple[str, ...]:
    """``given`` as a non-empty tuple of distinct names of ``known``, in ``known``'s order.

    Raises
    ------
    ParameterError
        An empty list, an unknown or repeated name, or not a list of strings.
    """
    if isinstance(given, str) or not all(isinstance(c, str) for c in given):
        raise ParameterError(name, f"expected a list of names of {list(known)}, got {given!r}")
    chosen = list(given)
    if not chosen:
        raise ParameterError(name, f"must not be empty (choose from {', '.join(known)})")
    for c in chosen:
        if c not in known:
            raise ParameterError(name, f"unknown component {c!r} (known: {', '.join(known)})")
    if len(set(chosen)) != len(chosen):
        raise ParameterError(name, f"a component is repeated: {chosen}")
    return tuple(c for c in known if c in chosen)


def check_weight(value: float, name: str = "weight") -> float:
    """``value`` as a task weight: finite and > 0."""
    v = float(value)
    if not np.isfinite(v) or v <= 0.0:
        raise ParameterError(name, f"must be finite and > 0, got {value!r}")
    return v
