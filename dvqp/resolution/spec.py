"""What one resolution step is made of: tasks (in levels), the objective, limits, ``W``."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.limits import AccelerationLimit, Limit
from dvqp.objective.objective import Objective
from dvqp.tasks.task import Task, check_priority, check_weight

DEFAULT_TASK_WEIGHT = 1e4
"""``ρ`` of the hard tasks' slack (dimensionless relative to W): large, so a task is given
up last."""

MAX_LEVELS = 16
"""Most levels (distinct priorities of the hard tasks) a step takes: a step whose levels cannot
all be met together solves up to one QP per level, each with a backend of its own (150 levels
took 37 s to plan a bundled scene, 1 000 over 2 minutes), so more are refused when the step is
made, at load for a scene file."""
RANK_RCOND = 1e-6
"""A level's Jacobian whose smallest singular value is below this fraction of its largest
cannot be met even alone (its rows are dependent there)."""


@dataclass(frozen=True)
class StepSpec:
    """The ingredients of a step, shared by the QP and the pseudoinverse baseline.

    Parameters
    ----------
    tasks
        At least one hard task (e.g. :class:`~dvqp.tasks.ToolTask`), any soft tasks; kept in
        order of priority (1 first, tasks of one priority in the order given), so that each
        level's rows of ``A`` follow each other.
    objective
        ``w(Q)``, followed as ``g = λ ∂w/∂Q`` in the hard tasks' null space.
    limits
        Hard limits of the QP (ignored by the baseline); at most one acceleration limit.
    weights
        Diagonal of ``W`` (> 0), scalar or shape (n,).
    task_weight
        ``ρ`` of the hard tasks' slack in the relaxed problem, > 0.
    """

    tasks: tuple[Task, ...]
    objective: Objective = field(default_factory=Objective)
    limits: tuple[Limit, ...] = ()
    weights: ArrayLike = 1.0
    task_weight: float = DEFAULT_TASK_WEIGHT

    def __post_init__(self) -> None:
        tasks = tuple(self.tasks)
        object.__setattr__(self, "limits", tuple(self.limits))
        _check_kind("tasks", tasks, Task)
        _check_kind("limits", self.limits, Limit)
        if not any(t.hard for t in tasks):
            raise ParameterError("tasks", "need at least one hard task (e.g. ToolTask())")
        for i, task in enumerate(tasks):
            if task.hard:
                check_priority(task.priority, f"tasks[{i}].priority")
                check_weight(task.weight, f"tasks[{i}].weight")
        priorities = {t.priority for t in tasks if t.hard}
        if len(priorities) > MAX_LEVELS:
            raise ParameterError(
                "tasks",
                f"{len(priorities)} priorities: at most {MAX_LEVELS} levels (each level is a QP "
                "of its own where the levels cannot be met together; merge tasks into fewer "
                "priorities)",
            )
        ordered = sorted(tasks, key=lambda t: t.priority if t.hard else 0)
        object.__setattr__(self, "tasks", tuple(ordered))
        if sum(isinstance(limit, AccelerationLimit) for limit in self.limits) > 1:
            raise ParameterError("limits", "at most one AccelerationLimit in a step")
        w = np.asarray(self.weights, dtype=np.float64)
        if w.ndim > 1:
            raise ShapeError("weights", (-1,), w.shape)
        if not np.isfinite(w).all() or np.any(w <= 0):
            raise ParameterError("weights", "must be finite and > 0")
        object.__setattr__(self, "weights", _validate.readonly(w.copy()))
        tw = _validate.positive("task_weight", self.task_weight)
        object.__setattr__(self, "task_weight", tw)

    @property
    def levels(self) -> tuple[tuple[Task, ...], ...]:
        """The hard tasks by level: one tuple per priority, highest (1) first."""
        hard = [t for t in self.tasks if t.hard]
        priorities = sorted({t.priority for t in hard})
        return tuple(tuple(t for t in hard if t.priority == p) for p in priorities)

    @property
    def level_names(self) -> tuple[str, ...]:
        """What reports call each level: its tasks' labels (``"tool h, alpha"``)."""
        return tuple("; ".join(t.label for t in level) for level in self.levels)

    def diagonal(self, n: int) -> NDArray[np.float64]:
        """The diagonal of ``W`` for n joints, shape (n,)."""
        return _validate.broadcast("weights", self.weights, n)

    def with_extra(self, tasks: Sequence[Task] = (), limits: Sequence[Limit] = ()) -> StepSpec:
        """A copy with more tasks and limits appended."""
        return StepSpec(
            (*self.tasks, *tasks),
            self.objective,
            (*self.limits, *limits),
            self.weights,
            self.task_weight,
        )


def unmeetable(jacobian: NDArray[np.float64]) -> str | None:
    """Why a level whose rows are ``jacobian`` (m, n) cannot be met even alone, whatever the
    limits: more rows than joints, or rows dependent (rank below m, :data:`RANK_RCOND`); None
    if it can."""
    m, n = jacobian.shape
    if m > n:
        return f"it has {m} rows for {n} joints"
    s = np.linalg.svd(jacobian, compute_uv=False)
    if m and not s[-1] > RANK_RCOND * s[0]:
        rank = int(np.sum(s > RANK_RCOND * s[0]))
        return f"its {m} rows are dependent at the start (rank {rank})"
    return None


def _check_kind(name: str, items: Sequence[object], kind: type) -> None:
    for i, item in enumerate(items):
        if not isinstance(item, kind):
            raise ParameterError(f"{name}[{i}]", f"must be a dvqp.{kind.__name__} (derive from it)")
