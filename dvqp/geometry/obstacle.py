"""Obstacles in the developed view: shapes in the (l, z) plane, gathered into a set.

An obstacle is any :class:`~dvqp.geometry.shapes.Shape` (a circle, a branch inlet, a band, a
polygon, or one of your own). Differences in l are wrapped modulo ``2πR``, so an obstacle near
the seam ``l = ±πR`` acts on both sides of it. ``Obstacle`` is the circle, the paper's envelope.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes import Circle, Shape

_TAKEN = re.compile(r"height|probe|holder|(point|link)\d+|obstacles\[\d+\]")
"""What reports write after a part's ``/`` for other things (or parts): no obstacle's name."""

Obstacle = Circle
"""The paper's obstacle: a circle, ``Obstacle(center, radius, weight)``."""


class ObstacleSet:
    """An immutable sequence of obstacles (compared by identity).

    Parameters
    ----------
    obstacles
        The shapes, in the order their rows and labels follow.
    names
        Optional names, one per shape (None: unnamed), as a scene's ``name`` keys give them.

    Attributes
    ----------
    weights : ndarray, shape (J,)
        Objective weights ``w_j``.
    labels : tuple of str
        What every report calls each obstacle: its name, else ``"obstacles[j]"`` (0-based, as
        scene errors name it).
    """

    def __init__(
        self, obstacles: Sequence[Shape] = (), names: Sequence[str | None] | None = None
    ) -> None:
        self.obstacles = tuple(obstacles)
        for i, o in enumerate(self.obstacles):
            if not isinstance(o, Shape):
                raise ParameterError(f"obstacles[{i}]", "must be an obstacle shape")
        given = [None] * len(self.obstacles) if names is None else list(names)
        if len(given) != len(self.obstacles):
            raise ParameterError("names", f"expected {len(self.obstacles)}, got {len(given)}")
        self.labels = tuple(f"obstacles[{j}]" if n is None else n for j, n in enumerate(given))
        for j, name in enumerate(given):
            if name is not None:
                _check_name(name, self.labels[:j], f"obstacles[{j}].name")
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


def _check_name(name: str, before: Sequence[str], field: str) -> None:
    """Raise ParameterError(field) unless ``name`` can label an obstacle after ``before``."""
    reason = None
    if not isinstance(name, str) or not name or name != name.strip():
        reason = "must be a non-empty name without surrounding spaces"
    elif not name.isprintable() or "/" in name:
        reason = f"{name!r}: must be printable and have no '/' (labels read 'point3/<name>')"
    elif _TAKEN.fullmatch(name):
        reason = (
            f"{name!r} reads as another label (height, probe, holder, pointN, linkN, "
            "obstacles[N]): choose another"
        )
    elif name in before:
        reason = f"{name!r} already names obstacles[{list(before).index(name)}]"
    if reason:
        raise ParameterError(field, reason)
