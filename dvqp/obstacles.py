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
from dvqp.developed_view import wrap


@dataclass(frozen=True)
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


def stack(
    obstacles: Sequence[Obstacle],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Centres (J, 2), radii (J,) and weights (J,) of a sequence of obstacles."""
    if not obstacles:
        return np.zeros((0, 2)), np.zeros(0), np.zeros(0)
    centers = np.array([o.center for o in obstacles])
    radii = np.array([o.radius for o in obstacles])
    weights = np.array([o.weight for o in obstacles])
    return centers, radii, weights


def offsets(lz: ArrayLike, centers: ArrayLike, pipe_radius: float) -> NDArray[np.float64]:
    """``S_j − p_i`` with l wrapped, for k points and J centres: shape (J, k, 2), m."""
    d = np.asarray(centers, dtype=np.float64)[:, None, :] - np.asarray(lz, dtype=np.float64)[None]
    d[..., 0] = wrap(d[..., 0], pipe_radius)
    return d


def segment_offsets(
    lz: ArrayLike, centers: ArrayLike, pipe_radius: float, clamp: bool
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Closest points of the k−1 links ``[p_i, p_{i+1}]`` to J centres.

    Parameters
    ----------
    lz
        Body points in (l, z), m, shape (k, 2).
    centers
        Obstacle centres, m, shape (J, 2).
    pipe_radius
        m, for the l wrap.
    clamp
        Clamp the segment parameter to [0, 1] (for distances); if False it is returned raw
        (the objective uses only links whose closest point lies inside).

    Returns
    -------
    t : ndarray, shape (J, k−1)
        Segment parameter ``k`` of the closest point ``p̄ = p_i + t·(p_{i+1} − p_i)``
        (NaN-free: a zero-length link gives t = 0).
    r : ndarray, shape (J, k−1, 2)
        ``S_j − p̄`` with l wrapped, m.
    """
    p = np.asarray(lz, dtype=np.float64)
    seg = p[1:] - p[:-1]
    seg[:, 0] = wrap(seg[:, 0], pipe_radius)
    s = offsets(p[:-1], centers, pipe_radius)  # (J, k-1, 2)
    length2 = np.einsum("ij,ij->i", seg, seg)
    safe = np.where(length2 > 1e-18, length2, 1.0)
    t = np.where(length2 > 1e-18, np.einsum("jik,ik->ji", s, seg) / safe, 0.0)
    if clamp:
        t = np.clip(t, 0.0, 1.0)
    r = s - t[..., None] * seg[None]
    return t, r
