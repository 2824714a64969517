"""Circular obstacles in the developed view and the body's clearance to them.

An obstacle is a circle in the (l, z) plane (m). Differences in l are wrapped modulo
``2πR``, so a circle near the seam ``l = ±πR`` acts on both sides of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
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


def offsets(lz: ArrayLike, centers: ArrayLike, pipe_radius: float) -> NDArray[np.float64]:
    """``S_j − p_i`` with l wrapped, for k points and J centres: shape (J, k, 2), m."""
    d = np.asarray(centers, dtype=np.float64)[:, None, :] - np.asarray(lz, dtype=np.float64)[None]
    d[..., 0] = wrap(d[..., 0], pipe_radius)
    return d
