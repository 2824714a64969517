"""Where the arm is relative to the obstacles: signed distances of every guarded part.

The guarded parts are the k body points and the probe (the tool point), the k−1 body links and
the probe holder (last body point to the tool). A run's step measures them once per state
(:mod:`dvqp.geometry.measure`); :func:`proximity` measures one state on its own, with the same
compiled kernels, and :func:`distances` any points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.measure import ShapeArrays, measure_chain, penalties, user_rows
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import ProximityBuffers, as_struct

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeDistances:
    """Signed distances of m points (or segments) to J shapes.

    Attributes
    ----------
    distance : ndarray, shape (J, m)
        Signed distance, m (negative inside).
    normal : ndarray, shape (J, m, 2)
        ``∇d`` with respect to the point (for a segment: at its closest point).
    penalty : ndarray, shape (J, m)
        ``e`` of the objective, m² (negative inside).
    penalty_gradient : ndarray, shape (J, m, 2)
        ``∇e``, m.
    t : ndarray, shape (J, m)
        For segments: parameter in [0, 1] of the closest point (zeros for points).
    """

    distance: Array
    normal: Array
    penalty: Array
    penalty_gradient: Array
    t: Array


@dataclass(frozen=True)
class Proximity:
    """Signed distances of the k+1 guarded points and k guarded links to J obstacles.

    Index i < k is body point i+1, i = k the probe; link i < k−1 is body link i+1, link k−1
    the probe holder (see :func:`point_label`, :func:`link_label`).

    Attributes
    ----------
    points : ShapeDistances
        Arrays (J, k+1, ...).
    links : ShapeDistances
        Arrays (J, k, ...), at each link's closest point.
    """

    points: ShapeDistances
    links: ShapeDistances

    @classmethod
    def of(cls, near: ProximityBuffers) -> Proximity:
        """Views of proximity buffers."""
        points = ShapeDistances(near.point_distance, near.point_normal, near.point_penalty,
                                near.point_penalty_gradient,
                                np.zeros_like(near.point_distance))  # fmt: skip
        links = ShapeDistances(near.link_distance, near.link_normal, near.link_penalty,
                               near.link_penalty_gradient, near.link_t)  # fmt: skip
        return cls(points, links)

    @property
    def point_clearance(self) -> Array:
        """Signed clearance of each guarded point to each obstacle, m, shape (J, k+1)."""
        return self.points.distance

    @property
    def link_clearance(self) -> Array:
        """Signed clearance of each guarded link to each obstacle, m, shape (J, k)."""
        return self.links.distance

    @property
    def link_t(self) -> Array:
        """Parameter in [0, 1] of each link's closest point, shape (J, k)."""
        return self.links.t

    def min_clearance(self) -> float:
        """Smallest clearance of any guarded point or link, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        return float(min(self.point_clearance.min(), self.link_clearance.min()))

    def probe_clearance(self) -> float:
        """Smallest clearance of the probe and its holder, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        return float(min(self.point_clearance[:, -1].min(), self.link_clearance[:, -1].min()))

    def closest(self) -> tuple[float, str, int]:
        """The smallest clearance (m), the part that has it and the obstacle's index.

        Raises ValueError with no obstacle.
        """
        points, links = self.point_clearance, self.link_clearance
        k = points.shape[1] - 1
        j, i = np.unravel_index(int(np.argmin(points)), points.shape)
        lj, li = np.unravel_index(int(np.argmin(links)), links.shape)
        if links[lj, li] < points[j, i]:
            return float(links[lj, li]), link_label(int(li), k), int(lj)
        return float(points[j, i]), point_label(int(i), k), int(j)


def point_label(i: int, k: int) -> str:
    """Name of guarded point i (0-based) of a body with k points: ``"point3"`` or ``"probe"``."""
    return "probe" if i == k else f"point{i + 1}"


def link_label(i: int, k: int) -> str:
    """Name of guarded link i (0-based) of a body with k points: ``"link2"`` or ``"holder"``."""
    return "holder" if i == k - 1 else f"link{i + 1}"


def measure(shapes: Sequence[Shape], chain: Array, period: float, links: bool = True
            ) -> ProximityBuffers:  # fmt: skip
    """Every distance of the points ``chain`` (m, ≥ 2) and (if ``links``) the links between
    them to ``shapes``, penalties included, in new buffers (J, m) and (J, m − 1 or 0)."""
    packed = ShapeArrays.of(shapes, period)
    near = ProximityBuffers.allocate(len(shapes), chain.shape[0] - 1)
    if not links:
        near = replace(near, **{f: np.zeros((len(shapes), 0, *getattr(near, f).shape[2:]))
                                for f in _LINK_FIELDS})  # fmt: skip
    points = np.ascontiguousarray(chain, dtype=np.float64)
    measure_chain(as_struct(packed), points, as_struct(near))
    user_rows(shapes, packed.code, points, period, near)
    penalties(packed.size, as_struct(near))
    return near


_LINK_FIELDS = ("link_distance", "link_normal", "link_penalty", "link_penalty_gradient", "link_t")


def proximity(state: KinematicState, obstacles: ObstacleSet | Sequence[Shape]) -> Proximity:
    """The :class:`Proximity` of ``state``'s guarded parts to ``obstacles``."""
    shapes = tuple(obstacles)
    return Proximity.of(measure(shapes, np.array(state.guarded), 2.0 * np.pi * state.radius))


def min_clearance(state: KinematicState, obstacles: ObstacleSet | Sequence[Shape]) -> float:
    """Smallest signed clearance (m) of any guarded part to ``obstacles``.

    Negative inside an obstacle; ``inf`` with no obstacles.
    """
    if not len(obstacles):
        return math.inf
    return proximity(state, obstacles).min_clearance()


def distances(
    obstacles: ObstacleSet | Sequence[Shape], lz: Array, period: float
) -> tuple[Array, Array]:
    """Signed distances (J, m) and normals (J, m, 2) of m points ``lz`` (m, 2) to every
    obstacle (l differences wrapped modulo ``period``, m)."""
    points = np.asarray(lz, dtype=np.float64).reshape(-1, 2)
    chain = np.vstack([points, points[-1:]])  # a chain needs two points: the last, twice
    near = measure(tuple(obstacles), chain, period, links=False)
    m = points.shape[0]
    return near.point_distance[:, :m].copy(), near.point_normal[:, :m].copy()


def segment_distances(
    obstacles: ObstacleSet | Sequence[Shape], a: Array, b: Array, period: float
) -> tuple[Array, Array, Array]:
    """Smallest signed distances (J, m), their parameters ``t`` (J, m) and the normals there
    (J, m, 2) of m segments ``a → b`` (each (m, 2)) to every obstacle."""
    a2, b2 = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    chain = np.stack([a2, b2], axis=1).reshape(-1, 2)  # a0, b0, a1, b1, ...: links 0, 2, ...
    near = measure(tuple(obstacles), chain, period)
    cut = slice(0, None, 2)
    return (near.link_distance[:, cut].copy(), near.link_t[:, cut].copy(),
            near.link_normal[:, cut].copy())  # fmt: skip
