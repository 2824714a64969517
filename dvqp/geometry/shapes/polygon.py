"""A simple polygon in the (l, z) plane: a weld-on pad, a bracket, a rail.

Its compiled distances (:func:`polygon_point`, :func:`polygon_segment`) work in the polygon's
local frame, l measured from its reference ``l_ref`` (wrapped), with the vertices as arrays
``vl, vz`` of shape (V,).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.shapes import polygon_geometry as geo
from dvqp.geometry.shapes.shape import (
    HEIGHT_FIELD,
    Array,
    CompiledShape,
    Shape,
    ShapeKernels,
    checked_height,
)
from dvqp.kinematics.developed_view import wrap_period
from dvqp.workspace.wiring import overrides
from solvers.jit import njit


@dataclass(frozen=True, eq=False)
class Polygon(Shape):
    """A simple polygon (its edges do not cross), vertices listed either way round.

    Parameters
    ----------
    vertices
        ``[[l, z], ...]``, m, shape (V, 2), V >= 3, l unwrapped (a polygon may straddle the
        seam ``l = ±πR``).
    weight
        The objective weight ``w_j`` (>= 0).
    height
        m above the pipe surface, > 0 (default ``inf``: unbounded, a wall to the sky).
    """

    vertices: Array
    weight: float = 1.0
    height: float = math.inf
    kind: ClassVar[str] = "polygon"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "vertices": ("points", None),
        "weight": ("weight", 1.0),
        **HEIGHT_FIELD,
    }
    l_ref: float = field(init=False)
    local_vertices: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ShapeError("vertices", (-1, 2), v.shape)
        if v.shape[0] > 3 and np.array_equal(v[0], v[-1]):  # written closed: drop the repeat
            v = v[:-1]
        _check_simple(v)
        object.__setattr__(self, "vertices", _validate.readonly(v))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        object.__setattr__(self, "height", checked_height(self.height))
        l_ref = float(v[:, 0].mean())
        object.__setattr__(self, "l_ref", l_ref)
        object.__setattr__(self, "local_vertices", _validate.readonly(v - [l_ref, 0.0]))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Polygon:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`).

        Every vertex must lie within half the circumference of the vertices' mean l: a wider
        polygon would wrap onto itself around the pipe.
        """
        shape = cls(values["vertices"], values["weight"], values["height"])
        half = np.pi * pipe_radius
        if np.abs(shape.local_vertices[:, 0]).max() >= half:
            raise ParameterError(
                "vertices", f"spans more than the pipe's circumference (2πR = {2 * half:.4g} m)"
            )
        return shape

    @property
    def size(self) -> float:
        """``sqrt(area / π)``, m: the radius of the circle of the same area."""
        return float(np.sqrt(abs(geo.signed_area(self.vertices)) / np.pi))

    @property
    def z_range(self) -> tuple[float, float]:
        """Lowest and highest vertex z, m."""
        return float(self.vertices[:, 1].min()), float(self.vertices[:, 1].max())

    def compiled(self) -> CompiledShape | None:
        """``[l_ref, 0, 0, 0]`` and its vertices (l from ``l_ref``), measured by
        :func:`polygon_point` and :func:`polygon_segment`."""
        if overrides(self, Polygon, "point_distance", "segment_distance"):
            return None
        local = self.local_vertices
        low, high = local.min(axis=0), local.max(axis=0)
        box = (float(low[0]), float(high[0]), float(low[1]), float(high[1]))
        data = (float(self.l_ref), 0.0, 0.0, 0.0)
        return CompiledShape(KERNELS, data, box, local, convex=_convex(local))

    def outline(self) -> Array:
        """The vertices, closed."""
        return np.vstack([self.vertices, self.vertices[:1]])


def _convex(v: Array) -> bool:
    """Whether the simple polygon ``v`` (V, 2) is convex: every turn the same way round (a
    straight angle allowed)."""
    e = np.roll(v, -1, axis=0) - v
    turns = e[:, 0] * np.roll(e, -1, axis=0)[:, 1] - e[:, 1] * np.roll(e, -1, axis=0)[:, 0]
    return bool((turns >= 0.0).all() or (turns <= 0.0).all())


def _check_simple(v: Array) -> None:
    if v.shape[0] < 3:
        raise ParameterError("vertices", f"need at least 3 vertices, got {v.shape[0]}")
    if not np.isfinite(v).all():
        raise ParameterError("vertices", "must be finite")
    repeated = np.flatnonzero((v == np.roll(v, 1, axis=0)).all(axis=1))
    if repeated.size:
        raise ParameterError("vertices", f"vertex {int(repeated[0])} repeats the one before it")
    if geo.self_intersects(v):
        raise ParameterError("vertices", "the polygon's edges cross (it must be simple)")
    if abs(geo.signed_area(v)) < 1e-10:
        raise ParameterError("vertices", "the polygon has no area")


SAMPLES = 33
"""Samples along a segment that enters the polygon, before the golden-section search."""
GOLDEN_STEPS = 40
INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0


@njit
def polygon_point(pl: float, pz: float, vl: Array, vz: Array) -> tuple[float, float, float]:
    """``(d, ∂d/∂l, ∂d/∂z)`` of one point (local l) to the polygon of vertices ``vl, vz``
    (local, (V,) each): the distance to the nearest edge, negative inside (even-odd rule)."""
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


@njit
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


@njit
def _outside(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """A segment that does not cross the outline: closest at an end, or at its point nearest
    a vertex (two segments that do not cross are closest at an endpoint of one of them)."""
    da, gal, gaz = polygon_point(al, az, vl, vz)
    db, gbl, gbz = polygon_point(bl, bz, vl, vz)
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


@njit
def _deepest(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """A segment that enters: the smallest signed distance along it, by sampling then a
    golden-section search between the best sample's neighbours."""
    sl, sz = bl - al, bz - az
    best_k, best = 0, np.inf
    for k in range(SAMPLES):
        t = k / (SAMPLES - 1)
        d = polygon_point(al + t * sl, az + t * sz, vl, vz)[0]
        if d < best:
            best, best_k = d, k
    lo, hi = max(best_k - 1, 0) / (SAMPLES - 1), min(best_k + 1, SAMPLES - 1) / (SAMPLES - 1)
    x1, x2 = hi - INV_PHI * (hi - lo), lo + INV_PHI * (hi - lo)
    f1 = polygon_point(al + x1 * sl, az + x1 * sz, vl, vz)[0]
    f2 = polygon_point(al + x2 * sl, az + x2 * sz, vl, vz)[0]
    for _ in range(GOLDEN_STEPS):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - INV_PHI * (hi - lo)
            f1 = polygon_point(al + x1 * sl, az + x1 * sz, vl, vz)[0]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + INV_PHI * (hi - lo)
            f2 = polygon_point(al + x2 * sl, az + x2 * sz, vl, vz)[0]
    t = 0.5 * (lo + hi)
    d, nl, nz = polygon_point(al + t * sl, az + t * sz, vl, vz)
    if best < d:  # a kink exactly at a sample
        t = best_k / (SAMPLES - 1)
        d, nl, nz = polygon_point(al + t * sl, az + t * sz, vl, vz)
    return d, t, nl, nz


@njit
def polygon_segment(al: float, az: float, bl: float, bz: float, vl: Array, vz: Array):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of one segment: exact for a segment outside; for one that
    enters, the deepest point to the golden-section search's precision (1e-9 of its length)."""
    res = _outside(al, az, bl, bz, vl, vz)
    if res[0] < 0.0 or _crosses(al, az, bl, bz, vl, vz):
        res = _deepest(al, az, bl, bz, vl, vz)
    return res


@njit
def measure_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """:func:`polygon_point` of polygon j of ``shapes`` (``data[j] = [l_ref, 0, 0, 0]``, its
    vertices ``vl, vz[start[j]:stop[j]]``, l from ``l_ref``)."""
    a, b = shapes.start[j], shapes.stop[j]
    pl = wrap_period(pl - shapes.data[j, 0], shapes.period)
    return polygon_point(pl, pz, shapes.vl[a:b], shapes.vz[a:b])


@njit
def measure_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """:func:`polygon_segment` of polygon j of ``shapes`` (its ends' distances unused)."""
    a, b, period = shapes.start[j], shapes.stop[j], shapes.period
    la = wrap_period(al - shapes.data[j, 0], period)
    lb = la + wrap_period(bl - al, period)
    return polygon_segment(la, az, lb, bz, shapes.vl[a:b], shapes.vz[a:b])


KERNELS = ShapeKernels(measure_point, measure_segment, boxed=True)
"""How the compiled measurement measures a polygon (a part far from its box: the box's
distance)."""
