"""A simple polygon in the (l, z) plane: a weld-on pad, a bracket, a rail."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.shapes import polygon_geometry as geo
from dvqp.geometry.shapes.shape import Array, Shape, local, local_segments

_SAMPLES = 33
_GOLDEN_STEPS = 40
_INV_PHI = (np.sqrt(5.0) - 1.0) / 2.0


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
    """

    vertices: Array
    weight: float = 1.0
    kind: ClassVar[str] = "polygon"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "vertices": ("points", None),
        "weight": ("weight", 1.0),
    }
    """Scene keys -> (kind of value, default); kinds: point, length, interval, points, weight."""
    l_ref: float = field(init=False)
    local_vertices: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=np.float64)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ShapeError("vertices", (-1, 2), v.shape)
        _check_simple(v)
        object.__setattr__(self, "vertices", _validate.readonly(v))
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        l_ref = float(v[:, 0].mean())
        object.__setattr__(self, "l_ref", l_ref)
        object.__setattr__(self, "local_vertices", _validate.readonly(v - [l_ref, 0.0]))

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Polygon:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(values["vertices"], values["weight"])

    @property
    def size(self) -> float:
        """``sqrt(area / π)``, m: the radius of the circle of the same area."""
        return float(np.sqrt(abs(geo.signed_area(self.vertices)) / np.pi))

    @property
    def z_range(self) -> tuple[float, float]:
        """Lowest and highest vertex z, m."""
        return float(self.vertices[:, 1].min()), float(self.vertices[:, 1].max())

    def outline(self) -> Array:
        """The vertices, closed."""
        return np.vstack([self.vertices, self.vertices[:1]])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        """Distance to the nearest edge, negative inside (even-odd rule)."""
        return geo.signed_distance(local(lz, self.l_ref, period), self.local_vertices)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        """Exact for a segment that stays outside; the deepest point, found by sampling and a
        golden-section search, for one that enters. There the normal is the one at the deepest
        point (one side of a kink where it lies on the medial axis)."""
        la, lb = local_segments(a, b, self.l_ref, period)
        verts = self.local_vertices
        d, t, n = _outside(la, lb, verts)
        enters = geo.crossings(la, lb, verts, np.roll(verts, -1, axis=0)) | (d < 0.0)
        if enters.any():
            d[enters], t[enters], n[enters] = _deepest(la[enters], lb[enters], verts)
        return d, t, n


def _outside(la: Array, lb: Array, verts: Array) -> tuple[Array, Array, Array]:
    """Segment–polygon distance when they do not cross: at an endpoint, or at the segment's
    point closest to a vertex (in the plane, two segments that do not cross are closest at an
    endpoint of one of them)."""
    da, na = geo.signed_distance(la, verts)
    db, nb = geo.signed_distance(lb, verts)
    seg = lb - la
    len2 = np.maximum((seg * seg).sum(axis=1), 1e-30)
    tv = (((verts[None] - la[:, None]) * seg[:, None]).sum(axis=-1) / len2[:, None]).clip(0, 1)
    pv = la[:, None] + tv[..., None] * seg[:, None]  # (m, V, 2)
    away = pv - verts[None]
    dv = np.sqrt((away * away).sum(axis=-1))
    j = np.argmin(dv, axis=1)
    rows = np.arange(la.shape[0])
    best_v = dv[rows, j]
    nv = away[rows, j] / np.maximum(best_v, 1e-30)[:, None]
    d = np.minimum(np.minimum(da, db), best_v)
    t = np.where(d == da, 0.0, np.where(d == db, 1.0, tv[rows, j]))
    n = np.where((d == da)[:, None], na, np.where((d == db)[:, None], nb, nv))
    return d, t, n


def _deepest(la: Array, lb: Array, verts: Array) -> tuple[Array, Array, Array]:
    """Smallest signed distance along each segment: the best of ``_SAMPLES`` samples, refined
    by a golden-section search between its neighbours."""
    m, seg = la.shape[0], lb - la
    grid = np.linspace(0.0, 1.0, _SAMPLES)

    def sd(t: Array) -> Array:  # t: (m,) -> (m,)
        return geo.signed_distance(la + t[:, None] * seg, verts)[0]

    pts = (la[:, None] + grid[None, :, None] * seg[:, None]).reshape(-1, 2)
    values = geo.signed_distance(pts, verts)[0].reshape(m, _SAMPLES)
    k = np.argmin(values, axis=1)
    lo, hi = grid[np.maximum(k - 1, 0)], grid[np.minimum(k + 1, _SAMPLES - 1)]
    x1, x2 = hi - _INV_PHI * (hi - lo), lo + _INV_PHI * (hi - lo)
    f1, f2 = sd(x1), sd(x2)
    for _ in range(_GOLDEN_STEPS):
        left = f1 < f2
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
        x2n = np.where(left, x1, lo + _INV_PHI * (hi - lo))
        x1n = np.where(left, hi - _INV_PHI * (hi - lo), x2)
        f2n = np.where(left, f1, sd(x2n))
        f1n = np.where(left, sd(x1n), f2)
        x1, x2, f1, f2 = x1n, x2n, f1n, f2n
    t = 0.5 * (lo + hi)
    # the sampled best may still beat the refined point (a kink at a sample)
    t = np.where(sd(t) <= values[np.arange(m), k], t, grid[k])
    d, n = geo.signed_distance(la + t[:, None] * seg, verts)
    return d, t, n


def _check_simple(v: Array) -> None:
    if v.shape[0] < 3:
        raise ParameterError("vertices", f"need at least 3 vertices, got {v.shape[0]}")
    if not np.isfinite(v).all():
        raise ParameterError("vertices", "must be finite")
    if geo.self_intersects(v):
        raise ParameterError("vertices", "the polygon's edges cross (it must be simple)")
    if abs(geo.signed_area(v)) < 1e-10:
        raise ParameterError("vertices", "the polygon has no area")
