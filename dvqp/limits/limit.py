"""What a limit gives the QP: inequalities ``Constraint(G, h)`` or a ``Bounds`` box.

A limit is any object with a ``name`` and ``compute(state, dt)`` returning one of the two (the
:class:`Limit` protocol). :func:`dvqp.resolution.qp.build_qp` stacks the constraints in the
order the limits are given and intersects the boxes.

Compiled step. A limit may also provide ``kernel(plan)``, returning a
:class:`~dvqp.compiled.plan.Kernel` built once for a :class:`~dvqp.compiled.plan.StepPlan`, or
None when it adds nothing (a tilt limit with ``min_tilt = 0``, a damper without obstacles). It
raises NotImplementedError when it cannot be compiled (a user's damper, an obstacle shape
without a proximity kernel): the run then takes the reference path. A kernel of

- a **box** intersects its bounds into ``plan.lb``, ``plan.ub`` in place (``lb = max(lb,
  own)``, ``ub = min(ub, own)``); the engine resets them to ``∓inf`` before the step's bounds
  kernels, which then leave the reference's intersected box;
- **constraints** asks once for a fixed number of rows (``plan.constraint_rows(count)``) and
  writes all of them at every step: the rows ``compute`` returns, in the same order, and every
  row that ``compute`` would leave out at that state as ``G = 0``, ``h = +inf``.

Kernels read the step ``dt`` from ``plan.dt[0]`` and the state from ``plan.state`` (obstacle
dampers from ``plan.proximity(obstacles)``, self-collision from ``plan.self_pairs()``: the
``plan.geometry`` kernels run before them), all bound once as views of the plan's buffers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Constraint:
    """Linear inequalities ``G Q̇ ≤ h`` on the joint velocities, with a label per row.

    Attributes
    ----------
    G : ndarray, shape (p, n)
    h : ndarray, shape (p,)
        Usually m/s (a damper) or rad/s.
    describe : callable, optional
        Returns what each row holds, e.g. ``"point3/obstacle1"``; called only when
        :attr:`labels` is read, so the per-step hot path formats no strings.
    """

    G: NDArray[np.float64]
    h: NDArray[np.float64]
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per row (``"row{i}"`` where none was given)."""
        if self.describe is None:
            return tuple(f"row{i}" for i in range(self.rows))
        return self.describe()

    @property
    def rows(self) -> int:
        """Number of rows p."""
        return int(self.h.shape[0])

    @staticmethod
    def empty(n: int) -> Constraint:
        """No rows, for n variables."""
        return Constraint(np.zeros((0, n)), np.zeros(0))

    @staticmethod
    def stack(parts: Sequence[Constraint], n: int) -> Constraint:
        """All rows of ``parts`` in order (an empty constraint if there are none)."""
        parts = [p for p in parts if p.rows]
        if not parts:
            return Constraint.empty(n)
        if len(parts) == 1:
            return parts[0]

        def describe() -> tuple[str, ...]:
            return tuple(label for p in parts for label in p.labels)

        return Constraint(
            np.vstack([p.G for p in parts]), np.concatenate([p.h for p in parts]), describe
        )


@dataclass(frozen=True)
class Bounds:
    """Box ``lb ≤ Q̇ ≤ ub`` on the joint velocities, rad/s, each shape (n,)."""

    lb: NDArray[np.float64]
    ub: NDArray[np.float64]

    def intersect(self, other: Bounds) -> Bounds:
        """The tighter of two boxes."""
        return Bounds(np.maximum(self.lb, other.lb), np.minimum(self.ub, other.ub))


@runtime_checkable
class Limit(Protocol):
    """A hard limit of the QP step, linear in ``Q̇`` at the current state.

    Implement ``name`` and :meth:`compute`; pass the object in ``StepSpec.limits`` (or
    ``dvqp.plan(..., limits=[...])``). The pseudoinverse baseline ignores limits.
    """

    name: str

    def compute(self, state: KinematicState, dt: float) -> Constraint | Bounds:
        """The limit's rows at ``state`` for a step of ``dt`` seconds.

        Parameters
        ----------
        state
            Kinematics of this step (read-only).
        dt
            Step, s, > 0.
        """
        ...
