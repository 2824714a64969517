"""Signed distances of points and segments to dvqp's shapes, written independently in NumPy,
and shapes of one's own (:class:`Shape` subclasses) built on them.

dvqp measures its own shapes with compiled kernels only. These functions are the tests'
second implementation (the circle and band from the package's NumPy code before the
redesign, the polygon from plain edge geometry, the inlet's curve by a derivative-free
search), and :class:`UserCircle`, :class:`UserBand`, :class:`UserPolygon`,
:class:`UserInlet` are what a user writes: a :class:`Shape` with NumPy ``point_distance`` and
``segment_distance``. :func:`twin` gives the user shape of the same geometry as one of
dvqp's, so that a set of both can be compared row by row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon, Shape

Array = NDArray[np.float64]
TINY = 1e-12
"""m: closer than this to a circle's centre, a point has no normal (0)."""


def wrap(dl: ArrayLike, period: float) -> Array:
    """Differences in l wrapped into ``[−period/2, period/2)``."""
    return np.remainder(np.asarray(dl, dtype=np.float64) + 0.5 * period, period) - 0.5 * period


def short_way(a: Array, b: Array, period: float) -> Array:
    """``b`` moved by a whole period in l so that ``a → b`` is the short way round."""
    out = np.array(b, dtype=np.float64)
    out[..., 0] = a[..., 0] + wrap(out[..., 0] - a[..., 0], period)
    return out


# ---- circle: ‖S − p‖ − r, normal −(S − p)/‖S − p‖ ---------------------------------------


def _from_offsets(s: Array, radius: float) -> tuple[Array, Array]:
    dist = np.sqrt((s * s).sum(axis=-1))
    safe = np.where(dist > TINY, dist, 1.0)
    return dist - radius, np.where((dist > TINY)[..., None], -s / safe[..., None], 0.0)


def circle_points(center: Array, radius: float, lz: Array, period: float) -> tuple[Array, Array]:
    s = np.asarray(center, dtype=np.float64) - np.asarray(lz, dtype=np.float64)
    s[:, 0] = wrap(s[:, 0], period)
    return _from_offsets(s, radius)


def circle_segments(
    center: Array, radius: float, a: Array, b: Array, period: float
) -> tuple[Array, Array, Array]:
    """Closest point ``a + t (b − a)``, ``t = clip((S − a)·(b − a)/‖b − a‖², 0, 1)``."""
    seg = np.asarray(b, dtype=np.float64) - np.asarray(a, dtype=np.float64)
    seg[:, 0] = wrap(seg[:, 0], period)
    length2 = np.maximum((seg * seg).sum(axis=-1), 1e-18)  # a zero-length link: t = 0
    s = np.asarray(center, dtype=np.float64) - np.asarray(a, dtype=np.float64)
    s[:, 0] = wrap(s[:, 0], period)
    t = ((s * seg).sum(axis=-1) / length2).clip(0.0, 1.0)
    d, n = _from_offsets(s - t[:, None] * seg, radius)
    return d, t, n


# ---- band: max(z_min − z, z − z_max) -------------------------------------------------------


def band_points(z_min: float, z_max: float, lz: Array) -> tuple[Array, Array]:
    z = np.asarray(lz, dtype=np.float64)[:, 1]
    below, above = z_min - z, z - z_max
    normal = np.zeros((z.shape[0], 2))
    normal[:, 1] = np.where(below >= above, -1.0, 1.0)
    return np.maximum(below, above), normal


def band_segments(z_min: float, z_max: float, a: Array, b: Array) -> tuple[Array, Array, Array]:
    """Convex, piecewise linear along a segment: the least of its ends and its crossing of the
    middle line (there ``−width/2``, no gradient)."""
    za, zb = np.asarray(a)[:, 1], np.asarray(b)[:, 1]
    dz = zb - za
    flat = np.abs(dz) <= 1e-15
    crossing = np.where(flat, 0.0, (0.5 * (z_min + z_max) - za) / np.where(flat, 1.0, dz))
    candidates = np.stack([np.zeros_like(za), np.ones_like(za), crossing.clip(0.0, 1.0)])
    z = za[None] + candidates * dz[None]
    k = np.argmin(np.maximum(z_min - z, z - z_max), axis=0)
    t = candidates[k, np.arange(za.shape[0])]
    d, n = band_points(z_min, z_max, np.column_stack([np.zeros_like(t), za + t * dz]))
    n[(k == 2) & (t > 0.0) & (t < 1.0)] = 0.0
    return d, t, n


# ---- polygon: nearest edge, sign by the even-odd rule --------------------------------------


def polygon_points(vertices: Array, lz: Array, period: float) -> tuple[Array, Array]:
    """Signed distance and normal of m points, l measured from the vertices' mean l (wrapped)."""
    v = np.asarray(vertices, dtype=np.float64)
    ref = float(v[:, 0].mean())
    v = v - [ref, 0.0]
    p = np.array(lz, dtype=np.float64).reshape(-1, 2)
    p[:, 0] = wrap(p[:, 0] - ref, period)
    v0, edge = v, np.roll(v, -1, axis=0) - v  # (E, 2)
    w = p[:, None, :] - v0[None]  # (m, E, 2)
    len2 = (edge * edge).sum(axis=-1)
    t = ((w * edge[None]).sum(axis=-1) / len2).clip(0.0, 1.0)
    gap = w - t[..., None] * edge[None]  # point minus its closest point on each edge
    dist = np.sqrt((gap * gap).sum(axis=-1))
    nearest = np.argmin(dist, axis=1)
    rows = np.arange(p.shape[0])
    d = dist[rows, nearest]
    z0, z1 = v0[:, 1][None], np.roll(v, -1, axis=0)[:, 1][None]
    straddles = (z0 > p[:, 1:2]) != (z1 > p[:, 1:2])
    with np.errstate(divide="ignore", invalid="ignore"):
        x = v0[:, 0][None] + (p[:, 1:2] - z0) * edge[:, 0][None] / (z1 - z0)
    inside = (straddles & (p[:, 0:1] < x)).sum(axis=1) % 2 == 1
    sign = np.where(inside, -1.0, 1.0)
    normal = sign[:, None] * gap[rows, nearest] / np.where(d > 0.0, d, 1.0)[:, None]
    return sign * d, normal


def _segments_cross_outline(v: Array, a: Array, b: Array) -> Array:
    """Which segments ``a → b`` (local l) cross or touch an edge of the outline ``v``."""

    def orient(p: Array, q: Array, r: Array) -> Array:
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (
            r[..., 0] - p[..., 0]
        )

    A, B = a[:, None], b[:, None]
    C, D = v[None], np.roll(v, -1, axis=0)[None]
    o1, o2, o3, o4 = orient(A, B, C), orient(A, B, D), orient(C, D, A), orient(C, D, B)
    return ((o1 * o2 <= 0) & (o3 * o4 <= 0)).any(axis=1)


def polygon_segments(
    vertices: Array, a: Array, b: Array, period: float, samples: int = 1001
) -> tuple[Array, Array, Array]:
    """Smallest signed distance along each segment, its ``t`` and the normal there.

    A segment that stays outside is closest at an end or at its point nearest a vertex (exact).
    One that enters has its deepest point found by ``samples`` samples and a golden-section
    search between the best one's neighbours.
    """
    v = np.asarray(vertices, dtype=np.float64)
    ref = float(v[:, 0].mean())
    la = np.array(a, dtype=np.float64)
    la[:, 0] = wrap(la[:, 0] - ref, period)
    lb = short_way(la, np.array(b, dtype=np.float64) - [ref, 0.0], period)
    local = v - [ref, 0.0]
    big = 4.0 * period  # points in the local frame are never wrapped again below

    def signed(points: Array) -> tuple[Array, Array]:
        return polygon_points(local, points, big)

    m = la.shape[0]
    seg = lb - la
    len2 = (seg * seg).sum(axis=1)
    # outside: the ends and each segment's point nearest each vertex
    tv = ((local[None] - la[:, None]) * seg[:, None]).sum(axis=-1)
    tv = (tv / np.where(len2 > 0.0, len2, 1.0)[:, None]).clip(0.0, 1.0)  # (m, V)
    candidates = np.column_stack([np.zeros(m), np.ones(m), tv])
    at = la[:, None] + candidates[..., None] * seg[:, None]
    values = signed(at.reshape(-1, 2))[0].reshape(m, -1)
    best = np.argmin(values, axis=1)
    t = candidates[np.arange(m), best]
    enters = (values.min(axis=1) < 0.0) | _segments_cross_outline(local, la, lb)
    for i in np.flatnonzero(enters):
        t[i] = _deepest(lambda x, i=i: signed(la[i] + np.outer(x, seg[i]))[0], samples)
    d, n = signed(la + t[:, None] * seg)
    return d, t, n


def _deepest(f, samples: int) -> float:  # type: ignore[no-untyped-def]
    """``t`` in [0, 1] of the least of ``f`` (vectorised over t): the best of ``samples``
    samples, refined by a golden-section search between its neighbours."""
    grid = np.linspace(0.0, 1.0, samples)
    values = f(grid)
    k = int(np.argmin(values))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, samples - 1)]
    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
    f1, f2 = f(np.array([x1, x2]))
    for _ in range(60):
        if f1 < f2:
            hi, x2, f2 = x2, x1, f1
            x1 = hi - g * (hi - lo)
            f1 = f(np.array([x1]))[0]
        else:
            lo, x1, f1 = x1, x2, f2
            x2 = lo + g * (hi - lo)
            f2 = f(np.array([x2]))[0]
    t = 0.5 * (lo + hi)
    return float(t) if f(np.array([t]))[0] <= values[k] else float(grid[k])  # a kink at a sample


# ---- the user's shapes -------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class UserCircle(Shape):
    """A circle of one's own: the geometry of :class:`Circle`, measured in NumPy."""

    center: Array
    radius: float
    weight: float = 1.0

    @property
    def size(self) -> float:
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        return float(self.center[1] - self.radius), float(self.center[1] + self.radius)

    def outline(self) -> Array:
        a = np.linspace(0.0, 2.0 * np.pi, 65)
        return np.asarray(self.center) + self.radius * np.column_stack([np.cos(a), np.sin(a)])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        return circle_points(np.asarray(self.center), self.radius, lz, period)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        return circle_segments(np.asarray(self.center), self.radius, a, b, period)


@dataclass(frozen=True, eq=False)
class UserBand(Shape):
    """A band of one's own, measured in NumPy."""

    z_min: float
    z_max: float
    weight: float = 1.0

    @property
    def size(self) -> float:
        return 0.5 * (self.z_max - self.z_min)

    @property
    def z_range(self) -> tuple[float, float]:
        return self.z_min, self.z_max

    def outline(self) -> Array:
        return np.array([[np.nan, self.z_min], [np.nan, self.z_max]])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        return band_points(self.z_min, self.z_max, lz)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        return band_segments(self.z_min, self.z_max, a, b)


@dataclass(frozen=True, eq=False)
class UserPolygon(Shape):
    """A polygon of one's own with penalty size ``rho`` (m), measured in NumPy."""

    vertices: Array
    rho: float
    weight: float = 1.0

    @property
    def size(self) -> float:
        return self.rho

    @property
    def z_range(self) -> tuple[float, float]:
        return float(self.vertices[:, 1].min()), float(self.vertices[:, 1].max())

    def outline(self) -> Array:
        return np.vstack([self.vertices, self.vertices[:1]])

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        return polygon_points(self.vertices, lz, period)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        return polygon_segments(self.vertices, a, b, period)


# ---- inlet: the exact curve l = R asin(r cos φ / R), z = r sin φ, searched without derivatives --

INLET_GRID = 512
"""Outline points of the first search; the golden section refines the best one's bracket."""


def _inlet_curve(phi: Array, r: float, big: float) -> Array:
    return np.stack([big * np.arcsin(r * np.cos(phi) / big), r * np.sin(phi)], axis=-1)


def inlet_points(
    center: Array, r: float, big: float, lz: Array, period: float
) -> tuple[Array, Array]:
    """Nearest outline point of each point by a grid of φ then golden section on the squared
    distance; inside where ``(R sin(Δl/R))² + Δz² < r²`` (|Δl| < πR/2)."""
    p = np.asarray(lz, dtype=np.float64) - center
    p[:, 0] = wrap(p[:, 0], period)
    h = 2 * np.pi / INLET_GRID
    grid = np.arange(INLET_GRID) * h
    sq = ((_inlet_curve(grid, r, big)[None] - p[:, None]) ** 2).sum(axis=-1)
    lo = grid[sq.argmin(axis=1)] - h
    hi = lo + 2 * h
    g = (math.sqrt(5) - 1) / 2

    def dist2(phi: Array) -> Array:
        return ((_inlet_curve(phi, r, big) - p) ** 2).sum(axis=-1)

    for _ in range(64):
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        left = dist2(x1) < dist2(x2)
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
    off = p - _inlet_curve(0.5 * (lo + hi), r, big)
    d = np.sqrt((off**2).sum(axis=1))
    inside = (np.abs(p[:, 0]) < 0.5 * np.pi * big) & (
        (big * np.sin(p[:, 0] / big)) ** 2 + p[:, 1] ** 2 < r * r
    )
    sign = np.where(inside, -1.0, 1.0)
    return sign * d, sign[:, None] * off / np.maximum(d, 1e-300)[:, None]


def inlet_nearest_normals(
    center: Array, r: float, big: float, point: Array, period: float, within: float = 1e-9
) -> list[Array]:
    """Every unit normal ``±(p − c)/‖p − c‖`` of the point ``p`` at an outline point ``c`` as
    near as the nearest to within ``within`` (m): one where one outline point is nearest, two
    (or more) on the region's medial axis, where the distance has a kink and either side's
    normal is its gradient. Each local least of the grid is refined by golden section."""
    p = np.asarray(point, dtype=np.float64) - center
    p[0] = wrap(p[0], period)
    h = 2 * np.pi / INLET_GRID
    grid = np.arange(INLET_GRID) * h
    sq = ((_inlet_curve(grid, r, big) - p) ** 2).sum(axis=-1)
    least = (sq <= np.roll(sq, 1)) & (sq <= np.roll(sq, -1))
    g = (math.sqrt(5) - 1) / 2
    found = []
    for phi in grid[least]:
        lo, hi = phi - h, phi + h
        for _ in range(64):
            x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
            d1 = ((_inlet_curve(x1, r, big) - p) ** 2).sum()
            d2 = ((_inlet_curve(x2, r, big) - p) ** 2).sum()
            hi, lo = (x2, lo) if d1 < d2 else (hi, x1)
        off = p - _inlet_curve(0.5 * (lo + hi), r, big)
        found.append((math.sqrt((off**2).sum()), off))
    best = min(d for d, _ in found)
    inside = abs(p[0]) < 0.5 * np.pi * big and (big * np.sin(p[0] / big)) ** 2 + p[1] ** 2 < r * r
    sign = -1.0 if inside else 1.0
    return [sign * off / max(d, 1e-300) for d, off in found if d <= best + within]


def inlet_segments(
    center: Array, r: float, big: float, a: Array, b: Array, period: float
) -> tuple[Array, Array, Array]:
    """Least signed distance along each segment: 129 samples, then golden section between the
    best one's neighbours (the signed distance of a convex region is convex along a line)."""
    b = short_way(a, b, period)
    m = a.shape[0]

    def along(t: Array) -> Array:  # t (m, s): the signed distances there, (m, s)
        p = a[:, None] + t[..., None] * (b - a)[:, None]
        return inlet_points(center, r, big, p.reshape(-1, 2), period)[0].reshape(t.shape)

    ts = np.linspace(0, 1, 129)
    k = along(np.tile(ts, (m, 1))).argmin(axis=1)
    lo, hi = ts[np.maximum(k - 1, 0)], ts[np.minimum(k + 1, 128)]
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        f = along(np.column_stack([x1, x2]))
        left = f[:, 0] < f[:, 1]
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
    t = 0.5 * (lo + hi)
    d, n = inlet_points(center, r, big, a + t[:, None] * (b - a), period)
    return d, t, n


@dataclass(frozen=True, eq=False)
class UserInlet(Shape):
    """An inlet of one's own (the curve of :class:`Inlet`), measured in NumPy."""

    center: Array
    radius: float
    pipe_radius: float
    weight: float = 1.0

    @property
    def size(self) -> float:
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        return self.center[1] - self.radius, self.center[1] + self.radius

    def outline(self) -> Array:
        return self.center + _inlet_curve(
            np.linspace(0, 2 * np.pi, 200), self.radius, self.pipe_radius
        )

    def point_distance(self, lz: Array, period: float) -> tuple[Array, Array]:
        return inlet_points(self.center, self.radius, self.pipe_radius, lz, period)

    def segment_distance(self, a: Array, b: Array, period: float) -> tuple[Array, Array, Array]:
        return inlet_segments(self.center, self.radius, self.pipe_radius, a, b, period)


def twin(shape: Shape) -> Shape:
    """The user shape of the same geometry, weight and penalty size as one of dvqp's."""
    if isinstance(shape, Circle):
        return UserCircle(np.array(shape.center), shape.radius, shape.weight)
    if isinstance(shape, Band):
        return UserBand(shape.z_min, shape.z_max, shape.weight)
    if isinstance(shape, Inlet):
        return UserInlet(np.array(shape.center), shape.radius, shape.pipe_radius, shape.weight)
    if isinstance(shape, Polygon):
        return UserPolygon(np.array(shape.vertices), shape.size, shape.weight)
    raise TypeError(f"no twin for {type(shape).__name__}")
