"""Signed distances of the arm's guarded chain to every obstacle, compiled.

:class:`ShapeArrays` packs an obstacle sequence once; :func:`measure_chain` writes every
built-in shape's distances and normals into :class:`~dvqp.workspace.ProximityBuffers` (the
kernels of each shape's module, selected per row), :func:`user_rows` those of shapes of your
own (their NumPy methods), and :func:`penalties` every row's objective penalty
``e = d (d + 2ρ)`` and ``∇e = 2 (d + ρ) ∇d``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.broad_phase import box_bound, chain_box, obstacle_bound
from dvqp.geometry.shapes import Shape
from dvqp.geometry.shapes.band import band_point, band_segment
from dvqp.geometry.shapes.circle import circle_point, circle_segment
from dvqp.geometry.shapes.inlet import UNKNOWN, inlet_point, inlet_segment
from dvqp.geometry.shapes.polygon import polygon_point, polygon_segment
from dvqp.geometry.shapes.shape import BAND, CIRCLE, INLET, OTHER, POLYGON
from dvqp.kinematics.developed_view import wrap_period
from dvqp.workspace import ProximityBuffers
from solvers.jit import njit

Array = NDArray[np.float64]


@dataclass(frozen=True)
class ShapeArrays:
    """J obstacles as the compiled measurement reads them.

    Attributes
    ----------
    period : float
        ``2πR``, m.
    code : (J,) int64
        :data:`CIRCLE`, :data:`BAND`, :data:`POLYGON`, :data:`INLET` or :data:`OTHER`.
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
        farther than this from a polygon's or an inlet's box gets the box's distance and
        direction (a circle's or a band's exact distance costs less than a box's), unless
        :func:`~dvqp.geometry.real_links.real_links` finds that the row may matter (``inf``,
        the default: every row exact).
    """

    period: float
    code: NDArray[np.int64]
    data: Array
    start: NDArray[np.int64]
    stop: NDArray[np.int64]
    vl: Array
    vz: Array
    size: Array
    refine: Array
    box: Array
    far: Array

    @classmethod
    def of(cls, shapes: Sequence[Shape], period: float) -> ShapeArrays:
        """Pack ``shapes``: each as it says itself (:meth:`~dvqp.geometry.shapes.Shape.compiled`;
        a shape of your own :data:`OTHER`)."""
        count = len(shapes)
        code, data = np.full(count, OTHER, np.int64), np.zeros((count, 4))
        start, stop = np.zeros(count, np.int64), np.zeros(count, np.int64)
        vertices: list[Array] = []
        box, at = np.zeros((count, 4)), 0
        for j, shape in enumerate(shapes):
            packed = shape.compiled()
            if packed is None:
                continue
            code[j], data[j], box[j] = packed.code, packed.data, packed.box
            if packed.samples is not None:
                start[j], stop[j] = at, at + packed.samples.shape[0]
                vertices.append(packed.samples)
                at += packed.samples.shape[0]
        packed = np.concatenate(vertices) if vertices else np.zeros((0, 2))
        vl, vz = np.ascontiguousarray(packed[:, 0]), np.ascontiguousarray(packed[:, 1])
        return cls(
            float(period),
            code,
            data,
            start,
            stop,
            vl,
            vz,
            np.array([s.size for s in shapes], float),
            np.full(count, math.inf),
            box,
            np.full(count, math.inf),
        )


@njit
def shape_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """``(d, ∂d/∂l, ∂d/∂z)`` of a point to obstacle j."""
    code, data, period = shapes.code[j], shapes.data[j], shapes.period
    if code == CIRCLE:
        return circle_point(data[0], data[1], data[2], pl, pz, period)
    if code == BAND:
        d, nz = band_point(data[0], data[1], pz)
        return d, 0.0, nz
    a, b = shapes.start[j], shapes.stop[j]
    if code == INLET:
        return inlet_point(
            wrap_period(pl - data[0], period),
            pz - data[1],
            data[2],
            data[3],
            shapes.vl[a:b],
            shapes.vz[a:b],
        )
    return polygon_point(wrap_period(pl - data[0], period), pz, shapes.vl[a:b], shapes.vz[a:b])


@njit
def shape_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of a segment to obstacle j; ``a_end``, ``b_end`` the ends'
    :func:`shape_point` where known (else :data:`~.shapes.inlet.UNKNOWN`; an inlet's segment
    then needs no second measurement of them)."""
    code, data, period = shapes.code[j], shapes.data[j], shapes.period
    if code == CIRCLE:
        return circle_segment(data[0], data[1], data[2], al, az, bl, bz, period)
    if code == BAND:
        d, t, nz = band_segment(data[0], data[1], az, bz)
        return d, t, 0.0, nz
    a, b = shapes.start[j], shapes.stop[j]
    la = wrap_period(al - data[0], period)
    lb = la + wrap_period(bl - al, period)
    if code == INLET:
        if lb != wrap_period(bl - data[0], period):  # b measured at another period's copy
            b_end = UNKNOWN
        return inlet_segment(
            la,
            az - data[1],
            lb,
            bz - data[1],
            data[2],
            data[3],
            shapes.vl[a:b],
            shapes.vz[a:b],
            a_end,
            b_end,
        )
    return polygon_segment(la, az, lb, bz, shapes.vl[a:b], shapes.vz[a:b])


@njit
def point_row(shapes, j, chain, i, near, exact) -> None:  # type: ignore[no-untyped-def]
    """Point i's row to obstacle j: exact, or (unless ``exact``) its box bound if that is
    beyond ``shapes.far[j]`` (so a row not beyond it is exact)."""
    pl, pz = chain[i, 0], chain[i, 1]
    d, nl, nz = -1.0, 0.0, 0.0
    if not exact and (shapes.code[j] == POLYGON or shapes.code[j] == INLET):
        d, nl, nz = box_bound(shapes, j, pl, pz, pl, pz)
    if d <= shapes.far[j]:
        d, nl, nz = shape_point(shapes, j, pl, pz)
    near.point_distance[j, i] = d
    near.point_normal[j, i, 0], near.point_normal[j, i, 1] = nl, nz


@njit(inline="always")
def _end(shapes, near, j, i):  # type: ignore[no-untyped-def]
    """Point i's row to obstacle j as a segment's end: ``(d, n_l, n_z)`` where it is exact
    (not beyond ``shapes.far[j]``: :func:`point_row`), else unknown."""
    if not near.point_distance[j, i] <= shapes.far[j]:
        return UNKNOWN
    return near.point_distance[j, i], near.point_normal[j, i, 0], near.point_normal[j, i, 1]


@njit
def link_row(shapes, j, chain, i, near, exact) -> None:  # type: ignore[no-untyped-def]
    """Link i's row to obstacle j, as :func:`point_row` (a box bound has ``t = 0``); its ends'
    point rows, written before it, are not measured again where they are exact."""
    a, b = near.ends[i, 0], near.ends[i, 1]
    al, az, bl, bz = chain[a, 0], chain[a, 1], chain[b, 0], chain[b, 1]
    d, t, nl, nz = -1.0, 0.0, 0.0, 0.0
    if not exact and (shapes.code[j] == POLYGON or shapes.code[j] == INLET):
        d, nl, nz = box_bound(shapes, j, al, az, bl, bz)
    if d <= shapes.far[j]:
        d, t, nl, nz = shape_segment(
            shapes, j, al, az, bl, bz, _end(shapes, near, j, a), _end(shapes, near, j, b)
        )
    near.link_distance[j, i], near.link_t[j, i] = d, t
    near.link_normal[j, i, 0], near.link_normal[j, i, 1] = nl, nz


@njit
def measure_chain(shapes, chain, near) -> None:  # type: ignore[no-untyped-def]
    """Distances and normals of the points ``chain`` (m; columns l, z, ...) and of the links
    ``near.ends`` between them to every compiled obstacle, into ``near`` (a packed
    :class:`~dvqp.workspace.ProximityBuffers`); rows of :data:`OTHER` shapes are left alone.
    The broad phase: an obstacle whose box is farther than ``shapes.far`` from the chain's is
    skipped (``near.skipped``), its rows left alone, ``near.bound`` the boxes' distance
    (:func:`obstacle_bound`); a row farther than it from a polygon's or an inlet's box
    holds the box's distance (:func:`~.real_links.real_links` measures those that matter)."""
    l0, lo, hi, zlo, zhi = chain_box(chain, near.ends, shapes.period)
    for j in range(shapes.code.shape[0]):
        near.skipped[j] = False
        if shapes.code[j] == OTHER:
            continue
        bound = obstacle_bound(shapes, j, l0, lo, hi, zlo, zhi) if shapes.far[j] < math.inf else 0.0
        if bound > shapes.far[j]:
            near.skipped[j], near.bound[j] = True, bound
        elif shapes.code[j] == CIRCLE:
            _circle_rows(shapes, j, chain, near)
        else:
            for i in range(chain.shape[0]):
                point_row(shapes, j, chain, i, near, False)
            for i in range(near.ends.shape[0]):
                link_row(shapes, j, chain, i, near, False)


@njit(inline="always")
def _circle_rows(shapes, j, chain, near) -> None:  # type: ignore[no-untyped-def]
    """Every row of circle j, as :func:`point_row` and :func:`link_row` write them (exact),
    its data read once: a circle's 13 rows took 0.11 µs so, 1.4–1.6 µs through those two (whose
    calls, with the packed struct and the other kinds' branches, LLVM does not inline), timed
    in a loop over the states of a fifty-obstacles run."""
    cl, cz, r, period = shapes.data[j, 0], shapes.data[j, 1], shapes.data[j, 2], shapes.period
    distance, normal = near.point_distance, near.point_normal
    for i in range(chain.shape[0]):
        d, nl, nz = circle_point(cl, cz, r, chain[i, 0], chain[i, 1], period)
        distance[j, i], normal[j, i, 0], normal[j, i, 1] = d, nl, nz
    ends, distance, normal, at = near.ends, near.link_distance, near.link_normal, near.link_t
    for i in range(ends.shape[0]):
        a, b = ends[i, 0], ends[i, 1]
        d, t, nl, nz = circle_segment(
            cl, cz, r, chain[a, 0], chain[a, 1], chain[b, 0], chain[b, 1], period
        )
        distance[j, i], at[j, i], normal[j, i, 0], normal[j, i, 1] = d, t, nl, nz


@njit(inline="always")
def fill(near, j) -> None:  # type: ignore[no-untyped-def]
    """Obstacle j's point and link rows at its bound (``near.bound[j]``, m), no direction,
    ``t = 0``: a skipped obstacle's rows written (it stays skipped)."""
    bound = near.bound[j]
    for i in range(near.point_distance.shape[1]):
        near.point_distance[j, i] = bound
        near.point_normal[j, i, 0], near.point_normal[j, i, 1] = 0.0, 0.0
    for i in range(near.link_distance.shape[1]):
        near.link_distance[j, i], near.link_t[j, i] = bound, 0.0
        near.link_normal[j, i, 0], near.link_normal[j, i, 1] = 0.0, 0.0


@njit
def penalties(size, near) -> None:  # type: ignore[no-untyped-def]
    """Every row's penalty ``e = d (d + 2ρ)`` (m²) and ``∇e = 2 (d + ρ) ∇d`` (m), but those of
    an obstacle the broad phase skipped (its repulsion, acting only inside, is 0)."""
    for j in range(size.shape[0]):
        if near.skipped[j]:
            continue
        rho = size[j]
        for i in range(near.point_distance.shape[1]):
            d = near.point_distance[j, i]
            near.point_penalty[j, i] = d * (d + 2.0 * rho)
            for c in range(2):
                near.point_penalty_gradient[j, i, c] = 2.0 * (d + rho) * near.point_normal[j, i, c]
        for i in range(near.link_distance.shape[1]):
            d = near.link_distance[j, i]
            near.link_penalty[j, i] = d * (d + 2.0 * rho)
            for c in range(2):
                near.link_penalty_gradient[j, i, c] = 2.0 * (d + rho) * near.link_normal[j, i, c]


def user_rows(
    shapes: Sequence[Shape],
    code: NDArray[np.int64],
    chain: Array,
    period: float,
    near: ProximityBuffers,
) -> None:
    """Rows of the shapes of your own (code :data:`OTHER`): their NumPy ``point_distance`` of
    the points ``chain`` (m) and ``segment_distance`` of the links ``near.ends``, into
    ``near``."""
    lz, ends = np.ascontiguousarray(chain[:, :2]), near.ends
    for j in np.flatnonzero(code == OTHER):
        shape = shapes[j]
        near.point_distance[j], near.point_normal[j] = shape.point_distance(lz, period)
        if ends.shape[0]:
            d, t, n = shape.segment_distance(lz[ends[:, 0]], lz[ends[:, 1]], period)
            near.link_distance[j], near.link_t[j], near.link_normal[j] = d, t, n
