"""Obstacles in the developed view: shapes in the (l, z) plane, packed into a set per run.

An obstacle is any :class:`~dvqp.geometry.shapes.Shape` (a circle, a branch inlet, a band, a
polygon). Differences in l are wrapped modulo ``2πR``, so an obstacle near the seam
``l = ±πR`` acts on both sides of it. ``Obstacle`` is the circle, the paper's envelope.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes import Circle, Shape, ShapeDistances

Obstacle = Circle
"""The paper's obstacle: a circle, ``Obstacle(center, radius, weight)``."""


class ObstacleSet:
    """An immutable set of obstacles, grouped by shape (identity-hashed cache key).

    Parameters
    ----------
    obstacles
        The shapes, in the order their rows and labels (``obstacle1``, ...) follow.

    Attributes
    ----------
    weights : ndarray, shape (J,)
        Objective weights ``w_j``.
    """

    def __init__(self, obstacles: Sequence[Shape] = ()) -> None:
        self.obstacles = tuple(obstacles)
        for i, o in enumerate(self.obstacles):
            if not isinstance(o, Shape):
                raise ParameterError(f"obstacles[{i}]", "must be an obstacle shape")
        self.weights = _validate.readonly(np.array([o.weight for o in self.obstacles], float))
        groups: dict[type[Shape], list[int]] = {}
        for i, o in enumerate(self.obstacles):
            groups.setdefault(type(o), []).append(i)
        self._groups = [(cls, [self.obstacles[i] for i in idx]) for cls, idx in groups.items()]
        self._indices = [tuple(idx) for idx in groups.values()]
        order = [i for idx in groups.values() for i in idx]
        self._inverse = np.argsort(order) if order != sorted(order) else None

    @classmethod
    def of(cls, obstacles: ObstacleSet | Sequence[Shape]) -> ObstacleSet:
        """``obstacles`` itself if it is a set already (keeping its cache identity), else a new
        set of them."""
        return obstacles if isinstance(obstacles, ObstacleSet) else cls(obstacles)

    def groups(self) -> list[tuple[type[Shape], list[Shape], tuple[int, ...]]]:
        """The shapes grouped by class: ``(class, shapes, their indices in the set)``."""
        return [
            (c, shapes, idx) for (c, shapes), idx in zip(self._groups, self._indices, strict=True)
        ]

    def points(self, lz: np.ndarray, period: float) -> ShapeDistances:
        """Every obstacle against m points ``lz`` (m, 2): arrays (J, m, ...)."""
        parts = [cls.batch_points(shapes, lz, period) for cls, shapes in self._groups]
        return self._gather(parts, lz.shape[0])

    def segments(self, a: np.ndarray, b: np.ndarray, period: float) -> ShapeDistances:
        """Every obstacle against m segments ``a → b`` (each (m, 2))."""
        parts = [cls.batch_segments(shapes, a, b, period) for cls, shapes in self._groups]
        return self._gather(parts, a.shape[0])

    def _gather(self, parts: list[ShapeDistances], m: int) -> ShapeDistances:
        if not parts:
            return ShapeDistances(np.zeros((0, m)), np.zeros((0, m, 2)), np.zeros((0, m)),
                             np.zeros((0, m, 2)), np.zeros((0, m)))  # fmt: skip
        found = parts[0] if len(parts) == 1 else ShapeDistances.stack(parts)
        if self._inverse is None:
            return found
        i = self._inverse
        return ShapeDistances(found.distance[i], found.normal[i], found.penalty[i],
                         found.penalty_gradient[i], found.t[i])  # fmt: skip

    def __len__(self) -> int:
        return len(self.obstacles)

    def __getitem__(self, index: int) -> Shape:
        return self.obstacles[index]

    def __iter__(self) -> Iterator[Shape]:
        return iter(self.obstacles)

    def __repr__(self) -> str:
        return f"ObstacleSet({list(self.obstacles)!r})"
