"""Compiled (numba) signed distances of points and segments to a simple polygon.

Loops over the edges are cheap compiled and costly in NumPy for the 256-vertex outline of a
branch inlet, so the per-step geometry runs here. Vertices are in the polygon's local frame
(l measured from its reference), as arrays ``vl, vz`` of shape (V,); points likewise.
:func:`polygons` is the compiled step's proximity kernel of polygons and inlets.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel
from dvqp.geometry.shapes.shape import Array
from dvqp.geometry.shapes.shape_kernels import proximity_outputs, store, wrap

if TYPE_CHECKING:
    from dvqp.compiled.plan import ProximityBuffers, StepPlan
    from dvqp.geometry.shapes.polygon import Polygon

SAMPLES = 33
"""Samples along a segment that enters the polygon, before the golden-section search."""
GOLDEN_STEPS = 40
INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0


@njit(cache=True)
def _point(pl: float, pz: float, vl: Array, vz: Array) -> tuple[float, float, float]:
    """Signed distance of one point and its gradient ``(d, ∂d/∂l, ∂d/∂z)``."""
    n = vl.shape[0]
    best, cl, cz, inside, best_e = np.inf, 0.0, 0.0, False, 0
    for i in range(n):
        j = i + 1 if i + 1 < n else 0  # (i + 1) % n without an integer division
        el, ez = vl[j] - vl[i], vz[j] - vz[i]
        wl, wz = pl - vl[i], pz - vz[i]
        len2 = el * el + ez * ez
        t = (wl * el + wz * ez) / len2 if len2 > 0.0 else 0.0
        t = min(max(t, 0.0), 1.0)
        ql, qz = vl[i] + t * el, vz[i] + t * ez
        d = math.hypot(pl - ql, pz - qz)
        if d < best:
            best, cl, cz, best_e = d, ql, qz, i
        if (vz[i] > pz) != (vz[j] > pz):
            x = vl[i] + (pz - vz[i]) * (vl[j] - vl[i]) / (vz[j] - vz[i])
            if pl < x:
                inside = not inside
    sign = -1.0 if inside else 1.0
    if best > 1e-14:
        return sign * best, sign * (pl - cl) / best, sign * (pz - cz) / best
    j = (best_e + 1) % n  # on the outline: the edge's outward normal
    el, ez = vl[j] - vl[best_e], vz[j] - vz[best_e]
    norm = math.hypot(el, ez)
    area = 0.0
    for i in range(n):
        area += vl[i] * vz[(i + 1) % n] - vl[(i + 1) % n] * vz[i]
    turn = 1.0 if area > 0.0 else -1.0
    return 0.0, turn * ez / norm, -turn * el / norm


@njit(cache=True)
def points_signed_distance(pl: Array, pz: Array, vl: Array, vz: Array) -> tuple[Array, Array]:
    """Signed distances ``(m,)`` (negative inside) and gradients ``(m, 2)`` of m points."""
    m = pl.shape[0]
    d, g = np.empty(m), np.empty((m, 2))
    for k in range(m):
        d[k], g[k, 0], g[k, 1] = _point(pl[k], pz[k], vl, vz)
    return d, g


@njit(cache=True)
def _crosses(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array) -> bool:
    n = vl.shape[0]
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        o1 = (bl - al) * (vz[i] - az) - (bz - az) * (vl[i] - al)
        o2 = (bl - al) * (vz[j] - az) - (bz - az) * (vl[j] - al)
        o3 = (vl[j] - vl[i]) * (az - vz[i]) - (vz[j] - vz[i]) * (al - vl[i])
        o4 = (vl[j] - vl[i]) * (bz - vz[i]) - (vz[j] - vz[i]) * (bl - vl[i])
        if o1 * o2 <= 0.0 and o3 * o4 <= 0.0:
            return True
    return False


@njit(cache=True)
def _outside(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """A segment that does not cross the outline: closest at an end, or at its point nearest
    a vertex (two segments that do not cross are closest at an endpoint of one of them)."""
    da, gal, gaz = _point(al, az, vl, vz)
    db, gbl, gbz = _point(bl, bz, vl, vz)
    d, t, nl, nz = da, 0.0, gal, gaz
    if db < d:
        d, t, nl, nz = db, 1.0, gbl, gbz
    sl, sz = bl - al, bz - az
    len2 = sl * sl + sz * sz
    for i in range(vl.shape[0]):
        tv = ((vl[i] - al) * sl + (vz[i] - az) * sz) / len2 if len2 > 0.0 else 0.0
        tv = min(max(tv, 0.0), 1.0)
        ql, qz = al + tv * sl - vl[i], az + tv * sz - vz[i]
        dv = math.hypot(ql, qz)
        if dv < d:
            d, t, nl, nz = dv, tv, ql / dv, qz / dv
    return d, t, nl, nz


@njit(cache=True)
def _deepest(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """A segment that enters: the smallest signed distance along it, by sampling then a
    golden-section search between the best sample's neighbours."""
    sl, sz = bl - al, bz - az
    best_k, best = 0, np.inf
    for k in range(SAMPLES):
        t = k / (SAMPLES - 1)
        d = _point(al + t * sl, az + t * sz, vl, vz)[0]
        if d < best:
            best, best_k = d, k
    lo, hi = max(best_k - 1, 0) / (SAMPLES - 1), min(best_k + 1, SAMPLES - 1) / (SAMPLES - 1)
    x1, x2 = hi - INV_PHI * (hi - lo), lo + INV_PHI * (hi - lo)
    f1 = _point(al + x1 * sl, az + x1 * sz, vl, vz)[0]
    f2 = _point(al + x2 * sl, az + x2 * sz, vl, vz)[0]
    for _ in range(GOLDEN_STEPS):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - INV_PHI * (hi - lo)
            f1 = _point(al + x1 * sl, az + x1 * sz, vl, vz)[0]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + INV_PHI * (hi - lo)
            f2 = _point(al + x2 * sl, az + x2 * sz, vl, vz)[0]
    t = 0.5 * (lo + hi)
    d, nl, nz = _point(al + t * sl, az + t * sz, vl, vz)
    if best < d:  # a kink exactly at a sample
        t = best_k / (SAMPLES - 1)
        d, nl, nz = _point(al + t * sl, az + t * sz, vl, vz)
    return d, t, nl, nz


@njit(cache=True)
def _segment(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of one segment (see :func:`segments_signed_distance`)."""
    res = _outside(al, az, bl, bz, vl, vz)
    if res[0] < 0.0 or _crosses(al, az, bl, bz, vl, vz):
        res = _deepest(al, az, bl, bz, vl, vz)
    return res


@njit(cache=True)
def segments_signed_distance(
    al: Array, az: Array, bl: Array, bz: Array, vl: Array, vz: Array
) -> tuple[Array, Array, Array]:
    """Smallest signed distance ``(m,)`` along m segments, its parameter ``t`` ``(m,)`` and
    the gradient there ``(m, 2)``: exact for a segment outside; for one that enters, the
    deepest point to the golden-section search's precision (1e-9 of the length)."""
    m = al.shape[0]
    d, t, g = np.empty(m), np.empty(m), np.empty((m, 2))
    for k in range(m):
        d[k], t[k], g[k, 0], g[k, 1] = _segment(al[k], az[k], bl[k], bz[k], vl, vz)
    return d, t, g


@njit(cache=True)
def polygons(
    guarded: Array, period: float, vl: Array, vz: Array, starts: NDArray[np.int64],
    l_ref: Array, sizes: Array, indices: NDArray[np.int64],
    point_distance: Array, point_normal: Array, point_penalty: Array, point_gradient: Array,
    link_distance: Array, link_normal: Array, link_penalty: Array, link_gradient: Array,
    link_t: Array,
) -> None:  # fmt: skip
    """Polygons against the k+1 points and k links of ``guarded`` (k+1, 3), as
    :meth:`~dvqp.geometry.shapes.polygon.Polygon.point_distance` and ``segment_distance``.

    Polygon j has the local vertices ``vl, vz[starts[j]:starts[j + 1]]`` (m), reference
    ``l_ref[j]`` and penalty size ``sizes[j]`` (m); its results go to row ``indices[j]``
    (argument order: :mod:`dvqp.geometry.shapes.shape_kernels`).
    """
    m = guarded.shape[0]
    for j in range(indices.shape[0]):
        row, ref, rho = indices[j], l_ref[j], sizes[j]
        pvl, pvz = vl[starts[j] : starts[j + 1]], vz[starts[j] : starts[j + 1]]
        for i in range(m):
            pl = wrap(guarded[i, 0] - ref, period)
            d, nl, nz = _point(pl, guarded[i, 1], pvl, pvz)
            store(point_distance, point_normal, point_penalty, point_gradient, row, i,
                  d, nl, nz, rho)  # fmt: skip
        for i in range(m - 1):
            al = wrap(guarded[i, 0] - ref, period)
            bl = al + wrap(guarded[i + 1, 0] - guarded[i, 0], period)
            d, t, nl, nz = _segment(al, guarded[i, 1], bl, guarded[i + 1, 1], pvl, pvz)
            store(link_distance, link_normal, link_penalty, link_gradient, row, i,
                  d, nl, nz, rho)  # fmt: skip
            link_t[row, i] = t


def polygon_kernel(
    shapes: Sequence[Polygon], sizes: Sequence[float], indices: NDArray[np.int64],
    plan: StepPlan, buffers: ProximityBuffers,
) -> Kernel:  # fmt: skip
    """The kernel of :func:`polygons` for ``shapes`` with penalty sizes ``sizes`` (m), their
    vertices packed once into flat arrays."""
    counts = [p.local_vertices.shape[0] for p in shapes]
    starts = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    vl = np.concatenate([p.local_vertices[:, 0] for p in shapes])
    vz = np.concatenate([p.local_vertices[:, 1] for p in shapes])
    l_ref = np.array([p.l_ref for p in shapes], dtype=np.float64)
    rho = np.array(sizes, dtype=np.float64)
    args = (plan.state.guarded, plan.period, vl, vz, starts, l_ref, rho, indices)
    return Kernel(polygons, (*args, *proximity_outputs(buffers)))
