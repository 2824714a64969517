"""The pieces a QP step is assembled from: inequalities ``Constraint(G, h)`` and ``Bounds``."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class Constraint:
    """Linear inequalities ``G x ≤ h`` on the joint velocities, with a label per row.

    Attributes
    ----------
    G : ndarray, shape (p, n)
    h : ndarray, shape (p,)
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
    """Box ``lb ≤ x ≤ ub`` on the joint velocities, rad/s, each shape (n,)."""

    lb: NDArray[np.float64]
    ub: NDArray[np.float64]

    def intersect(self, other: Bounds) -> Bounds:
        """The tighter of two boxes."""
        return Bounds(np.maximum(self.lb, other.lb), np.minimum(self.ub, other.ub))
