"""Signed distances of the arm's guarded chain to every obstacle, compiled.

:class:`ShapeArrays` packs an obstacle sequence once, each obstacle with the addresses of its
kind's kernels (:meth:`~dvqp.geometry.shapes.Shape.compiled`): :func:`measure_chain` calls
them by those addresses (:func:`solvers.linking.indirect`), so that a run compiles the kinds it
measures and no other; :func:`user_rows` writes the rows of shapes of your own (their NumPy
methods), and :func:`penalties` every row's objective penalty ``e = d (d + 2ρ)`` and
``∇e = 2 (d + ρ) ∇d``.

The kernels measure an obstacle's footprint; a point's row to an obstacle with a height is
the solid's (:func:`~dvqp.geometry.solid.solid`, its normal with respect to ``[l, z, h]``),
while a link's row stays its straight DV segment's footprint distance, from which
:mod:`dvqp.geometry.real_links` and :func:`~dvqp.geometry.link_pieces.straight_solids` derive
the links' clearances to the solid.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import types
from numpy.typing import NDArray

from dvqp.geometry.broad_phase import box_bound, chain_box, obstacle_bound
from dvqp.geometry.shapes import Shape
from dvqp.geometry.shapes.shape import UNKNOWN, ShapeKernels
from dvqp.geometry.solid import solid
from dvqp.workspace import ProximityBuffers, struct_type
from solvers.jit import njit
from solvers.linking import address_of, indirect

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeArrays:
    """J obstacles as the compiled measurement reads them.

    Attributes
    ----------
    period : float
        ``2πR``, m.
    data : (J, 4)
        A circle's ``[l, z, r, 0]``, a band's ``[z_min, z_max, 0, 0]``, a polygon's
        ``[l_ref, 0, 0, 0]``, an inlet's ``[l0, z0, r, R]``.
    start, stop : (J,) int64
        A polygon's vertices ``vl, vz[start:stop]``, an inlet's outline samples.
    vl, vz : (V,)
        Every polygon's vertices, l measured from its ``l_ref``; every inlet's samples
        (:attr:`~dvqp.geometry.shapes.Inlet.samples`, from its centre).
    size : (J,)
        ``ρ`` of each obstacle's penalty, m.
    height : (J,)
        Each obstacle's height above the pipe surface, m (``inf``: unbounded).
    refine : (J,)
        Below what clearance (m) a link's to each obstacle is measured on its real DV image to
        the last :data:`~dvqp.geometry.bend.PRECISION` (its obstacle damper's margin,
        0 if none: ``inf`` until set; see :func:`~dvqp.geometry.real_links.real_links`).
    box : (J, 4)
        ``[l_lo, l_hi, z_lo, z_hi]`` (m) of each obstacle, l from ``data[0]`` (a band's
        ``l`` unbounded).
    far : (J,)
        The broad phase (m): an obstacle whose box is farther than this from the box of the
        whole chain gets that distance (a lower bound, no direction) in every row; else a part
        farther than this from a ``boxed`` obstacle's box gets the box's distance and
        direction (a circle's or a band's exact distance costs less than a box's), unless
        :func:`~dvqp.geometry.real_links.real_links` finds that the row may matter (``inf``,
        the default: every row exact).
    point_at, segment_at, rows_at : (J,) int64
        The addresses of each obstacle's kind's kernels
        (:class:`~dvqp.geometry.shapes.shape.ShapeKernels`), compiled for this struct; 0: none
        (a shape of your own, measured in NumPy; ``rows_at``: its rows a call each).
    boxed, ends : (J,) bool
        Its kind's :attr:`~dvqp.geometry.shapes.shape.ShapeKernels.boxed` and ``ends``.
    convex : (J,) bool
        Whether its footprint is convex (:attr:`~dvqp.geometry.shapes.shape.CompiledShape.convex`).
    """

    period: float
    data: Array
    start: NDArray[np.int64]
    stop: NDArray[np.int64]
    vl: Array
    vz: Array
    size: Array
    height: Array
    refine: Array
    box: Array
    far: Array
    point_at: NDArray[np.int64]
    segment_at: NDArray[np.int64]
    rows_at: NDArray[np.int64]
    boxed: NDArray[np.bool_]
    ends: NDArray[np.bool_]
    convex: NDArray[np.bool_]

    @classmethod
    def of(cls, shapes: Sequence[Shape], period: float) -> ShapeArrays:
        """Pack ``shapes``, each as it says itself (:meth:`~dvqp.geometry.shapes.Shape.compiled`;
        a shape of your own has no kernels), its kind's kernels compiled (or loaded from the
        cache) for this struct."""
        count = len(shapes)
        data, box = np.zeros((count, 4)), np.zeros((count, 4))
        start, stop = np.zeros(count, np.int64), np.zeros(count, np.int64)
        boxed, ends = np.zeros(count, np.bool_), np.zeros(count, np.bool_)
        convex = np.zeros(count, np.bool_)
        vertices: list[Array] = []
        compiled, at = [shape.compiled() for shape in shapes], 0
        for j, packed in enumerate(compiled):
            if packed is None:
                continue
            data[j], box[j] = packed.data, packed.box
            boxed[j], ends[j] = packed.kernels.boxed, packed.kernels.ends
            convex[j] = packed.convex
            if packed.samples is not None:
                start[j], stop[j] = at, at + packed.samples.shape[0]
                vertices.append(packed.samples)
                at += packed.samples.shape[0]
        samples = np.concatenate(vertices) if vertices else np.zeros((0, 2))
        arrays = cls(
            float(period),
            data,
            start,
            stop,
            np.ascontiguousarray(samples[:, 0]),
            np.ascontiguousarray(samples[:, 1]),
            np.array([s.size for s in shapes], float),
            np.array([s.height for s in shapes], float),
            np.full(count, math.inf),
            box,
            np.full(count, math.inf),
            np.zeros(count, np.int64),
            np.zeros(count, np.int64),
            np.zeros(count, np.int64),
            boxed,
            ends,
            convex,
        )
        arrays._link([None if packed is None else packed.kernels for packed in compiled])
        return arrays

    @property
    def bounded(self) -> NDArray[np.bool_]:
        """(J,) bool: the obstacles with a height."""
        return np.isfinite(self.height)  # type: ignore[no-any-return]

    @property
    def compiled(self) -> NDArray[np.bool_]:
        """(J,) bool: the obstacles the compiled measurement measures (the others are shapes of
        your own)."""
        return self.point_at != 0  # type: ignore[no-any-return]

    def _link(self, kernels: Sequence[ShapeKernels | None]) -> None:
        """Each obstacle's kind's kernel addresses, the kernels compiled for this struct."""
        kind = struct_type(self)
        found: dict[int, tuple[int, int, int]] = {}
        for j, k in enumerate(kernels):
            if k is None:
                continue
            if id(k) not in found:
                rows = 0 if k.rows is None else address_of(k.rows, (kind, *_ROWS, _near_type()))
                found[id(k)] = (
                    address_of(k.point, (kind, *_POINT)),
                    address_of(k.segment, (kind, *_SEGMENT)),
                    rows,
                )
            self.point_at[j], self.segment_at[j], self.rows_at[j] = found[id(k)]


_END = types.UniTuple(types.float64, 3)
_POINT = (types.int64, types.float64, types.float64)
"""A point kernel's arguments after ``shapes``: ``j, pl, pz``."""
_SEGMENT = (types.int64, *(types.float64,) * 4, _END, _END)
"""A segment kernel's arguments after ``shapes``: ``j, al, az, bl, bz, a_end, b_end``."""
_ROWS = (types.int64, types.Array(types.float64, 2, "C"))
"""A rows kernel's arguments between ``shapes`` and ``near``: ``j, chain``."""
_point_at = indirect(types.UniTuple(types.float64, 3), (None, *_POINT))
_segment_at = indirect(types.UniTuple(types.float64, 4), (None, *_SEGMENT))
_rows_at = indirect(types.none, (None, *_ROWS, None))
_NEAR: list[Any] = []


def _near_type() -> Any:
    """The struct type of :class:`~dvqp.workspace.ProximityBuffers` (made once)."""
    if not _NEAR:
        _NEAR.append(struct_type(ProximityBuffers.sized(0, 0, np.zeros((0, 2), np.int64))))
    return _NEAR[0]


@njit
def shape_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """``(d, ∂d/∂l, ∂d/∂z)`` of a point to obstacle j: its kind's ``point`` kernel."""
    return _point_at(shapes.point_at[j], shapes, j, pl, pz)


@njit
def shape_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of a segment to obstacle j: its kind's ``segment`` kernel;
    ``a_end``, ``b_end`` the ends' :func:`shape_point` where known (else
    :data:`~.shapes.shape.UNKNOWN`; a kind that uses them, ``ends``, then measures them
    once)."""
    return _segment_at(shapes.segment_at[j], shapes, j, al, az, bl, bz, a_end, b_end)


@njit(separate=True)
def point_row(shapes, j, chain, i, near, exact) -> None:  # type: ignore[no-untyped-def]
    """Point i's row to obstacle j: exact, or (unless ``exact``) its box bound if that is
    beyond ``shapes.far[j]`` (so a row not beyond it is exact)."""
    pl, pz = chain[i, 0], chain[i, 1]
    d, nl, nz = -1.0, 0.0, 0.0
    if not exact and shapes.boxed[j]:
        d, nl, nz = box_bound(shapes, j, pl, pz, pl, pz)
    if d <= shapes.far[j]:
        d, nl, nz = shape_point(shapes, j, pl, pz)
    height = shapes.height[j]
    if height < math.inf:  # the solid's row (a footprint's bound lifts to the solid's)
        d, w2, wh = solid(d, chain[i, 2] - height)
        nl, nz = w2 * nl, w2 * nz
        near.point_normal[j, i, 2] = wh
    near.point_distance[j, i] = d
    near.point_normal[j, i, 0], near.point_normal[j, i, 1] = nl, nz


@njit(separate=True, python=True)  # also for shapes of your own (user_rows)
def lift_points(height, h, distance, normal) -> None:  # type: ignore[no-untyped-def]
    """Points' footprint rows to an obstacle of ``height`` (m) made the solid's, in place:
    ``distance`` (m,) and ``normal`` (m, 3) (its [l, z] part the footprint's) of the points
    at heights ``h`` (m,)."""
    for i in range(distance.shape[0]):
        d, w2, wh = solid(distance[i], h[i] - height)
        distance[i] = d
        normal[i, 0], normal[i, 1], normal[i, 2] = w2 * normal[i, 0], w2 * normal[i, 1], wh


@njit(inline="always")
def _end(shapes, near, j, i):  # type: ignore[no-untyped-def]
    """Point i's row to obstacle j as a segment's end: ``(d, n_l, n_z)`` where it is exact
    (not beyond ``shapes.far[j]``: :func:`point_row`) and the footprint's (no height), else
    unknown."""
    if not near.point_distance[j, i] <= shapes.far[j] or shapes.height[j] < math.inf:
        return UNKNOWN
    return near.point_distance[j, i], near.point_normal[j, i, 0], near.point_normal[j, i, 1]


@njit(separate=True)
def link_row(shapes, j, chain, i, near, exact) -> None:  # type: ignore[no-untyped-def]
    """Link i's row to obstacle j, as :func:`point_row` (a box bound has ``t = 0``); its ends'
    point rows, written before it, are not measured again where they are exact."""
    a, b = near.ends[i, 0], near.ends[i, 1]
    al, az, bl, bz = chain[a, 0], chain[a, 1], chain[b, 0], chain[b, 1]
    d, t, nl, nz = -1.0, 0.0, 0.0, 0.0
    if not exact and shapes.boxed[j]:
        d, nl, nz = box_bound(shapes, j, al, az, bl, bz)
    if d <= shapes.far[j]:
        d, t, nl, nz = shape_segment(
            shapes, j, al, az, bl, bz, _end(shapes, near, j, a), _end(shapes, near, j, b)
        )
    near.link_distance[j, i], near.link_t[j, i] = d, t
    near.link_normal[j, i, 0], near.link_normal[j, i, 1] = nl, nz


@njit(separate=True)
def measure_chain(shapes, chain, near) -> None:  # type: ignore[no-untyped-def]
    """Distances and normals of the points ``chain`` (m; columns l, z, ...) and of the links
    ``near.ends`` between them to every compiled obstacle, into ``near`` (a packed
    :class:`~dvqp.workspace.ProximityBuffers`); rows of shapes of your own are left alone.
    The broad phase: an obstacle whose box is farther than ``shapes.far`` from the chain's is
    skipped (``near.skipped``), its rows left alone, ``near.bound`` the boxes' distance
    (:func:`obstacle_bound`); a row farther than it from a ``boxed`` obstacle's box holds the
    box's distance (:func:`~.real_links.real_links` measures those that matter). A kind with
    a ``rows`` kernel writes all of an obstacle's rows at once (its point rows then made the
    solid's, :func:`lift_points`)."""
    l0, lo, hi, zlo, zhi = chain_box(chain, near.ends, shapes.period)
    for j in range(shapes.point_at.shape[0]):
        near.skipped[j] = False
        if shapes.point_at[j] == 0:
            continue
        bound = obstacle_bound(shapes, j, l0, lo, hi, zlo, zhi) if shapes.far[j] < math.inf else 0.0
        if bound > shapes.far[j]:
            near.skipped[j], near.bound[j] = True, bound
        elif shapes.rows_at[j] != 0:
            _rows_at(shapes.rows_at[j], shapes, j, chain, near)
            if shapes.height[j] < math.inf:
                lift_points(
                    shapes.height[j], chain[:, 2], near.point_distance[j], near.point_normal[j]
                )
        else:
            for i in range(chain.shape[0]):
                point_row(shapes, j, chain, i, near, False)
            for i in range(near.ends.shape[0]):
                link_row(shapes, j, chain, i, near, False)


@njit(inline="always")
def fill(near, j) -> None:  # type: ignore[no-untyped-def]
    """Obstacle j's point and link rows at its bound (``near.bound[j]``, m), no direction,
    ``t = 0``: a skipped obstacle's rows written (it stays skipped)."""
    bound = near.bound[j]
    for i in range(near.point_distance.shape[1]):
        near.point_distance[j, i] = bound
        near.point_normal[j, i, 0], near.point_normal[j, i, 1] = 0.0, 0.0
        near.point_normal[j, i, 2] = 0.0
    for i in range(near.link_distance.shape[1]):
        near.link_distance[j, i], near.link_t[j, i] = bound, 0.0
        near.link_normal[j, i, 0], near.link_normal[j, i, 1] = 0.0, 0.0


@njit(separate=True)
def penalties(shapes, near) -> None:  # type: ignore[no-untyped-def]
    """Every row's penalty ``e = d (d + 2ρ)`` (m²) and ``∇e = 2 (d + ρ) ∇d`` (m, with respect
    to ``[l, z, h]``), but those of an obstacle the broad phase skipped (its repulsion, acting
    only inside, is 0). A link's is its straight DV segment's: the footprint's row, or for an
    obstacle with a height the solid's (``near.straight_*``); ``link_penalty_at`` the segment
    parameters its [l, z] part and its h part hold at."""
    for j in range(shapes.size.shape[0]):
        if near.skipped[j]:
            continue
        rho, bounded = shapes.size[j], shapes.height[j] < math.inf
        for i in range(near.point_distance.shape[1]):
            d = near.point_distance[j, i]
            near.point_penalty[j, i] = d * (d + 2.0 * rho)
            for c in range(3):
                near.point_penalty_gradient[j, i, c] = 2.0 * (d + rho) * near.point_normal[j, i, c]
        for i in range(near.link_distance.shape[1]):
            if bounded:
                d, n = near.straight_distance[j, i], near.straight_normal[j, i]
                at, at_h = near.straight_at[j, i, 0], near.straight_at[j, i, 1]
                nl, nz, nh = n[0], n[1], n[2]
            else:
                d, at = near.link_distance[j, i], near.link_t[j, i]
                nl, nz, nh, at_h = near.link_normal[j, i, 0], near.link_normal[j, i, 1], 0.0, at
            near.link_penalty[j, i] = d * (d + 2.0 * rho)
            scale = 2.0 * (d + rho)
            gradient = near.link_penalty_gradient[j, i]
            gradient[0], gradient[1], gradient[2] = scale * nl, scale * nz, scale * nh
            near.link_penalty_at[j, i, 0], near.link_penalty_at[j, i, 1] = at, at_h


def user_rows(
    shapes: Sequence[Shape],
    compiled: NDArray[np.bool_],
    chain: Array,
    period: float,
    near: ProximityBuffers,
) -> None:
    """Rows of the shapes of your own (not ``compiled``): their NumPy ``point_distance`` of
    the points ``chain`` (m) and ``segment_distance`` of the links ``near.ends``, into
    ``near`` (a point's made the solid's where the shape has a height)."""
    lz, ends = np.ascontiguousarray(chain[:, :2]), near.ends
    for j in np.flatnonzero(~compiled):
        shape = shapes[j]
        near.point_distance[j], near.point_normal[j, :, :2] = shape.point_distance(lz, period)
        if shape.bounded:
            heights = np.ascontiguousarray(chain[:, 2])
            lift_points(shape.height, heights, near.point_distance[j], near.point_normal[j])
        if ends.shape[0]:
            d, t, n = shape.segment_distance(lz[ends[:, 0]], lz[ends[:, 1]], period)
            near.link_distance[j], near.link_t[j], near.link_normal[j] = d, t, n
