"""Circular obstacles in the developed view and the body's clearance to them.

An obstacle is a circle in the (l, z) plane (m). Differences in l are wrapped modulo
``2πR``, so a circle near the seam ``l = ±πR`` acts on both sides of it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import wrap


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A circle in the (l, z) plane of the developed view.

    Parameters
    ----------
    center
        ``[l, z]`` of the centre, m, shape (2,).
    radius
        Radius, m, > 0.
    weight
        The objective weight ``w_j`` (>= 0).
    """

    center: NDArray[np.float64]
    radius: float
    weight: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "center", _validate.readonly(_validate.vector("center", self.center, 2))
        )
        object.__setattr__(self, "radius", _validate.positive("radius", self.radius))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))


class ObstacleSet:
    """An immutable set of obstacle circles, packed as arrays (identity-hashed cache key).

    Parameters
    ----------
    obstacles
        The circles.

    Attributes
    ----------
    centers : ndarray, shape (J, 2)
        ``[l, z]`` of each centre, m.
    radii : ndarray, shape (J,)
        m.
    weights : ndarray, shape (J,)
        Objective weights ``w_j``.
    """

    def __init__(self, obstacles: Sequence[Obstacle] = ()) -> None:
        self.obstacles = tuple(obstacles)
        for i, o in enumerate(self.obstacles):
            if not isinstance(o, Obstacle):
                raise ParameterError(f"obstacles[{i}]", "must be an Obstacle")
        ro = _validate.readonly
        if self.obstacles:
            self.centers = ro(np.array([o.center for o in self.obstacles]))
            self.radii = ro(np.array([o.radius for o in self.obstacles]))
            self.weights = ro(np.array([o.weight for o in self.obstacles]))
        else:
            self.centers, self.radii, self.weights = (
                ro(np.zeros((0, 2))),
                ro(np.zeros(0)),
                ro(np.zeros(0)),
            )

    @classmethod
    def of(cls, obstacles: ObstacleSet | Sequence[Obstacle]) -> ObstacleSet:
        """``obstacles`` itself if it is a set already (keeping its cache identity), else a new
        set of them."""
        return obstacles if isinstance(obstacles, ObstacleSet) else cls(obstacles)

    def __len__(self) -> int:
        return len(self.obstacles)

    def __getitem__(self, index: int) -> Obstacle:
        return self.obstacles[index]

    def __iter__(self):  # type: ignore[no-untyped-def]
        return iter(self.obstacles)

    def __repr__(self) -> str:
        return f"ObstacleSet({list(self.obstacles)!r})"


def offsets(lz: ArrayLike, centers: ArrayLike, pipe_radius: float) -> NDArray[np.float64]:
    """``S_j − p_i`` with l wrapped, for k points and J centres: shape (J, k, 2), m."""
    d = np.asarray(centers, dtype=np.float64)[:, None, :] - np.asarray(lz, dtype=np.float64)[None]
    d[..., 0] = wrap(d[..., 0], pipe_radius)
    return d
