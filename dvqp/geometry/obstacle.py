"""Obstacles in the developed view: shapes in the (l, z) plane, gathered into a set.

An obstacle is any :class:`~dvqp.geometry.shapes.Shape` (a circle, a branch inlet, a band, a
polygon, or one of your own). Differences in l are wrapped modulo ``2πR``, so an obstacle near
the seam ``l = ±πR`` acts on both sides of it. ``Obstacle`` is the circle, the paper's envelope.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes import Circle, Shape

Obstacle = Circle
"""The paper's obstacle: a circle, ``Obstacle(center, radius, weight)``."""


class ObstacleSet:
    """An immutable sequence of obstacles (compared by identity).

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

    @classmethod
    def of(cls, obstacles: ObstacleSet | Sequence[Shape]) -> ObstacleSet:
        """``obstacles`` itself if it is a set already, else a new set of them."""
        return obstacles if isinstance(obstacles, ObstacleSet) else cls(obstacles)

    def __len__(self) -> int:
        return len(self.obstacles)

    def __getitem__(self, index: int) -> Shape:
        return self.obstacles[index]

    def __iter__(self) -> Iterator[Shape]:
        return iter(self.obstacles)

    def __repr__(self) -> str:
        return f"ObstacleSet({list(self.obstacles)!r})"
