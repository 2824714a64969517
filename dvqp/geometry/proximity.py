"""Where the arm is relative to the obstacles: signed distances of every guarded part.

The guarded parts are the k body points, the probe (the tool point) and the rail point (where
the carriage rides its rail, if the arm has one), the k−1 body links, the probe holder (last
body point to the tool) and the carriage link (rail point to body point 1). A run's step
measures them once per state (:mod:`dvqp.geometry.measure`); :func:`proximity` measures one
state on its own, with the same compiled kernels, and :func:`distances` any points.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.link_pieces import straight_solids
from dvqp.geometry.measure import ShapeArrays, measure_chain, penalties, user_rows
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.real_links import real_links
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import PartNames, ProximityBuffers, as_struct, link_ends

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeDistances:
    """Signed distances of m points (or segments) to J shapes.

    Attributes
    ----------
    distance : ndarray, shape (J, m)
        Signed distance to the obstacle's solid, m (negative inside).
    normal : ndarray, shape (J, m, 3)
        ``∇d`` with respect to the point's ``[l, z, h]`` (for a segment: at its closest point).
    penalty : ndarray, shape (J, m)
        ``e`` of the objective, m² (negative inside).
    penalty_gradient : ndarray, shape (J, m, 3)
        ``∇e``, m.
    t : ndarray, shape (J, m)
        For segments: parameter in [0, 1] of the closest point (zeros for points).
    t_height : ndarray, shape (J, m), optional
        For the straight segments' rows to an obstacle with a height: the parameter of the
        point whose height the row's h part holds (its piece's lower end; ``t`` elsewhere).
        The row's ``∇d`` is shared between the segment's ends as ``(1 − t, t)`` in its
        ``[l, z]`` part and ``(1 − t_height, t_height)`` in its h part. None: ``t``.
    """

    distance: Array
    normal: Array
    penalty: Array
    penalty_gradient: Array
    t: Array
    t_height: Array | None = None


@dataclass(frozen=True)
class Proximity:
    """Signed distances of the m guarded points and L guarded links to J obstacles.

    Index i < k is body point i+1, i = k the probe, i = k+1 the rail point; link i < k−1 is
    body link i+1, link k−1 the probe holder, link k the carriage link (their names:
    ``names``).

    Attributes
    ----------
    points : ShapeDistances
        Arrays (J, m, ...).
    links : ShapeDistances
        Arrays (J, L, ...) of the straight DV segments between the links' ends, at each one's
        closest point (the objective's; to an obstacle with a height the solid's, ``t`` its
        footprint part's).
    real : ShapeDistances
        Of the links' real DV images (``dvqp.geometry.real_links``): distance, normal, link
        parameter ``t`` (no penalty: zeros). The limits keep these, and reports show them.
    names : PartNames
        The guarded parts' names.
    bounded : ndarray of bool, shape (J,), optional
        Which obstacles have a height (None: none).
    """

    points: ShapeDistances
    links: ShapeDistances
    real: ShapeDistances
    names: PartNames
    bounded: NDArray[np.bool_] | None = None

    @property
    def k(self) -> int:
        """Number of body points."""
        return self.names.k

    @classmethod
    def of(
        cls, near: ProximityBuffers, names: PartNames, bounded: NDArray[np.bool_] | None = None
    ) -> Proximity:
        """Views of proximity buffers of the guarded parts ``names`` (the links' straight rows
        copied, the solid's for the obstacles ``bounded`` (J,) that have a height)."""
        points = ShapeDistances(
            near.point_distance,
            near.point_normal,
            near.point_penalty,
            near.point_penalty_gradient,
            np.zeros_like(near.point_distance),
        )
        lifted = np.zeros(near.skipped.shape, bool) if bounded is None else bounded
        distance = np.where(lifted[:, None], near.straight_distance, near.link_distance)
        flat = np.concatenate([near.link_normal, np.zeros_like(near.link_t)[..., None]], axis=-1)
        links = ShapeDistances(
            distance,
            np.where(lifted[:, None, None], near.straight_normal, flat),
            near.link_penalty,
            near.link_penalty_gradient,
            near.link_penalty_at[..., 0].copy(),
            near.link_penalty_at[..., 1].copy(),
        )
        none = np.zeros_like(near.real_distance)
        real = ShapeDistances(
            near.real_distance,
            near.real_normal,
            none,
            np.zeros_like(near.real_normal),
            near.real_at,
        )
        return cls(points, links, real, names, None if bounded is None else lifted)

    @property
    def point_clearance(self) -> Array:
        """Signed clearance of each guarded point to each obstacle, m, shape (J, m)."""
        return self.points.distance

    @property
    def link_clearance(self) -> Array:
        """Signed clearance of each guarded link (its real DV image) to each obstacle, m,
        shape (J, L)."""
        return self.real.distance

    @property
    def link_t(self) -> Array:
        """Parameter in [0, 1] of each link's closest point, shape (J, L)."""
        return self.real.t

    def min_clearance(self) -> float:
        """Smallest clearance of any guarded point or link, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        return float(min(self.point_clearance.min(), self.link_clearance.min()))

    def probe_clearance(self) -> float:
        """Smallest clearance of the probe and its holder, m (``inf`` with no obstacle)."""
        if self.points.distance.shape[0] == 0:
            return math.inf
        k = self.k
        return float(min(self.point_clearance[:, k].min(), self.link_clearance[:, k - 1].min()))

    def closest(self) -> tuple[float, str, int]:
        """The smallest clearance (m), the part that has it and the obstacle's index.

        Raises ValueError with no obstacle.
        """
        d, part, j, _ = self._closest()
        return d, part, j

    def closest_side(self) -> str:
        """Where the closest part (:meth:`closest`) is from its obstacle, if that obstacle has
        a height: ``"over"`` it (clear of its top face), ``"beside"`` it (clear of its side,
        below its top), ``"past its edge"`` (both), ``"inside"``; ``""`` for an unbounded
        obstacle (always beside it).

        Raises ValueError with no obstacle.
        """
        d, _, j, normal = self._closest()
        if self.bounded is None or not self.bounded[j]:
            return ""
        footprint, height = float(np.hypot(normal[0], normal[1])), float(normal[2])
        if d < 0.0:
            return "inside"
        if height == 0.0:
            return "beside"
        return "over" if footprint == 0.0 else "past its edge"

    def _closest(self) -> tuple[float, str, int, Array]:
        """``(d, part, j, ∇d)`` of the closest part (see :meth:`closest`)."""
        points, links, names = self.point_clearance, self.link_clearance, self.names
        j, i = np.unravel_index(int(np.argmin(points)), points.shape)
        lj, li = np.unravel_index(int(np.argmin(links)), links.shape)
        if links[lj, li] < points[j, i]:
            normal = self.real.normal[lj, li]
            return float(links[lj, li]), names.link(int(li)), int(lj), normal
        return float(points[j, i]), names.point(int(i)), int(j), self.points.normal[j, i]


def measure(
    shapes: Sequence[Shape],
    chain: Array,
    period: float,
    ends: NDArray[np.int64],
    real: tuple[Array, float, int] | None = None,
) -> ProximityBuffers:
    """Every distance of the points ``chain`` (m; columns l, z, h) and of the links ``ends``
    (L, 2) between them to ``shapes``, penalties included, in new buffers (J, m) and (J, L);
    with ``real`` (the points' 3-D origins (m, 3), the pipe's radius, m, and the probe's
    index), also the links' real clearances. A chain of two columns (l, z) is measured
    against the obstacles' footprints (as if ``h = −∞``: every distance the footprint's)."""
    packed = ShapeArrays.of(shapes, period)
    near = ProximityBuffers.sized(len(shapes), chain.shape[0], ends)
    points = np.full((chain.shape[0], 3), -np.inf)  # writable, C: the run's kernel types
    points[:, : chain.shape[1]] = chain
    measure_chain(as_struct(packed), points, as_struct(near))
    user_rows(shapes, packed.compiled, points, period, near)
    if real is not None:
        real_links(as_struct(packed), points, *real, as_struct(near))
    straight_solids(as_struct(packed), points, as_struct(near))
    penalties(as_struct(packed), as_struct(near))
    return near


def measure_state(
    state: KinematicState, obstacles: ObstacleSet | Sequence[Shape]
) -> ProximityBuffers:
    """Every distance of ``state``'s guarded parts to ``obstacles`` (the links' real ones
    included), in new buffers, as a run's step measures them with every row exact."""
    return measure(
        tuple(obstacles),
        np.array(state.guarded),
        2.0 * np.pi * state.radius,
        link_ends(state.k, state.rail),
        (np.array(state.origins), state.radius, state.k),
    )


def proximity(state: KinematicState, obstacles: ObstacleSet | Sequence[Shape]) -> Proximity:
    """The :class:`Proximity` of ``state``'s guarded parts to ``obstacles``."""
    bounded = np.array([o.bounded for o in obstacles], bool)
    return Proximity.of(measure_state(state, obstacles), state.part_names, bounded)


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
    """Signed distances (J, m) and normals of m points to every obstacle (l differences
    wrapped modulo ``period``, m): of points ``lz`` (m, 2) to the obstacles' footprints in the
    (l, z) plane, normals (J, m, 2); of points ``[l, z, h]`` (m, 3) to their solids (each
    footprint up to its height), normals (J, m, 3) with respect to ``[l, z, h]``."""
    given = np.asarray(lz, dtype=np.float64)
    width = 3 if given.ndim > 1 and given.shape[-1] == 3 else 2
    near = measure(tuple(obstacles), given.reshape(-1, width), period, np.zeros((0, 2), np.int64))
    return near.point_distance, near.point_normal[..., :width]


def segment_distances(
    obstacles: ObstacleSet | Sequence[Shape], a: Array, b: Array, period: float
) -> tuple[Array, Array, Array]:
    """Smallest signed distances (J, m) of m segments ``a → b`` (each (m, 2)) to every
    obstacle's footprint in the (l, z) plane, their parameters ``t`` (J, m) and the normals
    there (J, m, 2)."""
    a2, b2 = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    chain = np.concatenate([a2, b2]).reshape(-1, 2)
    m = a2.reshape(-1, 2).shape[0]
    ends = np.stack([np.arange(m), np.arange(m, 2 * m)], axis=1)  # a_i → b_i
    near = measure(tuple(obstacles), chain, period, ends)
    return near.link_distance, near.link_t, near.link_normal
