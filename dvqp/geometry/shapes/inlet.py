"""A branch inlet: a perpendicular tube of radius r meeting the pipe, as seen developed.

A tube of radius ``r < R`` whose axis meets the pipe axis at ``(l0, z0)`` at a right angle
cuts the pipe surface along ``(R sin((l − l0)/R))² + (z − z0)² = r²``: a circle stretched in l,
``Δl = R asin(r cos φ / R)``, ``Δz = r sin φ``: a convex curve (each direction is the
tangent at exactly two points, see :func:`inlet_segment`). Its compiled distances
(:func:`inlet_point`, :func:`inlet_segment`) measure that curve itself, in the inlet's local
frame (l and z from its centre, l wrapped): no polygon stands for it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.shapes.shape import (
    HEIGHT_FIELD,
    UNKNOWN,
    Array,
    CompiledShape,
    Shape,
    ShapeKernels,
    checked_height,
)
from dvqp.kinematics.developed_view import wrap_period
from dvqp.workspace.wiring import overrides
from solvers.jit import njit

SAMPLES = 32
"""Outline points, at ``φ = 2πk/SAMPLES``, that bracket the nearest point's parameter."""
NEWTON_STEPS = 40
GOLDEN_STEPS = 60
BRACKET_STEPS = 120
"""Most false-position steps of the deepest point of a segment that enters."""
INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0
_ON = 1e-14
"""m: a point this close to the outline is on it (its normal: the outline's)."""
_POINT2 = 1e-18
"""m²: a shorter segment is a point (its nearer end)."""


@dataclass(frozen=True, eq=False)
class Inlet(Shape):
    """A branch tube meeting the pipe at a right angle.

    Parameters
    ----------
    center
        ``[l0, z0]``, m: where the branch axis meets the pipe axis.
    radius
        ``r``, m, ``0 < r < pipe_radius``.
    pipe_radius
        ``R``, m.
    weight
        The objective weight ``w_j`` (>= 0).
    height
        m above the pipe surface, > 0 (default ``inf``: unbounded, a wall to the sky).
    """

    center: NDArray[np.float64]
    radius: float
    pipe_radius: float
    weight: float = 1.0
    height: float = math.inf
    kind: ClassVar[str] = "inlet"
    SCENE_FIELDS: ClassVar[dict[str, tuple[str, Any]]] = {
        "center": ("point", None),
        "radius": ("length", None),
        "weight": ("weight", 1.0),
        **HEIGHT_FIELD,
    }
    samples: Array = field(init=False, repr=False)

    def __post_init__(self) -> None:
        center = _validate.readonly(_validate.vector("center", self.center, 2))
        object.__setattr__(self, "center", center)
        r = _validate.positive("radius", self.radius)
        big = _validate.positive("pipe_radius", self.pipe_radius)
        if not r < big:
            raise ParameterError(
                "radius", f"{r:g} m must be smaller than the pipe radius {big:g} m"
            )
        object.__setattr__(self, "radius", r)
        object.__setattr__(self, "weight", _validate.positive("weight", self.weight, strict=False))
        object.__setattr__(self, "height", checked_height(self.height))
        samples = _validate.readonly(self.curve(SAMPLES) - self.center)
        object.__setattr__(self, "samples", samples)

    def curve(self, count: int) -> Array:
        """``count`` points of the exact outline, counter-clockwise, not closed, m."""
        phi = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
        r, big = self.radius, self.pipe_radius
        dl = big * np.arcsin(r * np.cos(phi) / big)
        return self.center + np.column_stack([dl, r * np.sin(phi)])

    @classmethod
    def from_scene(cls, values: dict[str, Any], pipe_radius: float) -> Inlet:
        """From a scene file's ``[[obstacles]]`` table (keys :attr:`SCENE_FIELDS`)."""
        return cls(
            values["center"], values["radius"], pipe_radius, values["weight"], values["height"]
        )

    @property
    def size(self) -> float:
        """The branch radius r, m."""
        return self.radius

    @property
    def z_range(self) -> tuple[float, float]:
        """``z0 ± r``, m."""
        return float(self.center[1] - self.radius), float(self.center[1] + self.radius)

    def compiled(self) -> CompiledShape | None:
        """``[l0, z0, r, R]`` and its outline samples (from its centre), measured by
        :func:`inlet_point` and :func:`inlet_segment`; its samples hold the tips
        (φ = 0, π): their box is exact."""
        if overrides(self, Inlet, "point_distance", "segment_distance"):
            return None
        (l, z), local = self.center, self.samples
        low, high = local.min(axis=0), local.max(axis=0)
        box = (float(low[0]), float(high[0]), float(low[1] + z), float(high[1] + z))
        data = (float(l), float(z), float(self.radius), float(self.pipe_radius))
        return CompiledShape(KERNELS, data, box, local, convex=True)  # convex for r < R

    def outline(self) -> Array:
        """512 points of the exact outline, closed."""
        points = self.curve(512)
        return np.vstack([points, points[:1]])


@njit(inline="always")
def _curve(phi, r, big):  # type: ignore[no-untyped-def]
    """``(Δl, Δz, Δl', Δz', Δl'', Δz'')`` of the outline at ``φ`` (m, m/rad, m/rad²)."""
    c, s = math.cos(phi), math.sin(phi)
    k = r * c / big
    root = math.sqrt(1.0 - k * k)
    dl1 = -r * s / root
    dl2 = -r * c / root + r * r * r * c * s * s / (big * big * root * root * root)
    return big * math.asin(k), r * s, dl1, r * c, dl2, -r * s


@njit
def _nearest(pl, pz, r, big, x, lo, hi):  # type: ignore[no-untyped-def]
    """``(φ, Δl, Δz, Δl', Δz')``: the ``φ`` in ``(lo, hi)`` where ``D' = 0``, by Newton's
    method from ``x``, and the outline there; ``φ`` is ``nan`` if a step would leave the
    bracket or ``D'' ≤ 0`` (then :func:`_golden` searches it). The outline at the last step's
    end is its Taylor polynomial of first order from where the step was computed (an error
    of ``~step²``, below 1e-20 m: the step is below 1e-10 rad), not one more evaluation."""
    nan = math.nan
    for _ in range(NEWTON_STEPS):
        dl, dz, l1, z1, l2, z2 = _curve(x, r, big)
        ol, oz = dl - pl, dz - pz
        f, fp = ol * l1 + oz * z1, l1 * l1 + z1 * z1 + ol * l2 + oz * z2  # ½ D', ½ D''
        if not fp > 0.0:
            return nan, nan, nan, nan, nan
        step = f / fp
        x -= step
        if not lo < x < hi:
            return nan, nan, nan, nan, nan
        if abs(step) < 1e-10:
            return x, dl - step * l1, dz - step * z1, l1 - step * l2, z1 - step * z2
    dl, dz, l1, z1, _, _ = _curve(x, r, big)
    return x, dl, dz, l1, z1


@njit
def _golden(pl, pz, r, big, lo, hi):  # type: ignore[no-untyped-def]
    """A least ``D`` in ``[lo, hi]`` by golden section (where the bracket is not clean)."""
    for _ in range(GOLDEN_STEPS):
        x1, x2 = hi - INV_PHI * (hi - lo), lo + INV_PHI * (hi - lo)
        a1, b1 = _curve(x1, r, big)[:2]
        a2, b2 = _curve(x2, r, big)[:2]
        if (a1 - pl) ** 2 + (b1 - pz) ** 2 < (a2 - pl) ** 2 + (b2 - pz) ** 2:
            hi = x2
        else:
            lo = x1
    return 0.5 * (lo + hi)


@njit
def inlet_point(pl, pz, r, big, sl, sz):  # type: ignore[no-untyped-def]
    """``(d, ∂d/∂l, ∂d/∂z)`` of the point ``(pl, pz)`` (m, from the centre, l wrapped) to the
    outline of branch radius ``r`` on a pipe of radius ``big``, negative inside. ``sl, sz``
    ((S,) each) are its points at ``φ_k = 2πk/S``: each one nearer than both neighbours
    brackets a local least distance, found by Newton's method on ``D'(φ) = 0``; the least of
    them is the distance, its normal ``(p − c)/‖p − c‖`` (the outline's outward normal on it).
    ``p − c`` is normal to the outline at the nearest point ``c``: ``p`` is inside where it
    points along the inward normal (the region is convex)."""
    n, h = sl.shape[0], 2.0 * math.pi / sl.shape[0]
    best, phi = math.inf, 0.0
    dl, dz, l1, z1 = math.nan, math.nan, math.nan, math.nan  # the outline at the nearest φ
    before = (sl[n - 1] - pl) ** 2 + (sz[n - 1] - pz) ** 2
    here = (sl[0] - pl) ** 2 + (sz[0] - pz) ** 2
    for k in range(n):
        j = k + 1 if k + 1 < n else 0
        after = (sl[j] - pl) ** 2 + (sz[j] - pz) ** 2
        if here <= before and here <= after:
            curve = before - 2.0 * here + after  # Newton from the samples' parabola's vertex
            guess = k * h + (0.5 * h * (before - after) / curve if curve > 0.0 else 0.0)
            x, cl, cz, cl1, cz1 = _nearest(pl, pz, r, big, guess, (k - 1) * h, (k + 1) * h)
            if x != x:  # nan: no clean Newton's step
                x = _golden(pl, pz, r, big, (k - 1) * h, (k + 1) * h)
                cl, cz, cl1, cz1, _, _ = _curve(x, r, big)
            d2 = (cl - pl) ** 2 + (cz - pz) ** 2
            if d2 < best:
                best, phi, dl, dz, l1, z1 = d2, x, cl, cz, cl1, cz1
        before, here = here, after
    if phi != phi or best == math.inf:  # no sample bracketed one (not finite): as before
        dl, dz, l1, z1, _, _ = _curve(phi, r, big)
    d = math.sqrt(best)
    sign = -1.0 if (pl - dl) * z1 - (pz - dz) * l1 < 0.0 else 1.0  # p − c along the normal?
    if d > _ON:
        return sign * d, sign * (pl - dl) / d, sign * (pz - dz) / d
    norm = math.hypot(l1, z1)
    return 0.0, z1 / norm, -l1 / norm


@njit
def _support(nl, nz, r, big):  # type: ignore[no-untyped-def]
    """``(Δl, Δz)`` of the outline point whose tangent is perpendicular to the unit ``n`` and
    where ``n`` points out (the other is ``(−Δl, −Δz)``)."""
    k2 = (r / big) ** 2 * nz * nz
    x2 = min(2.0 * nl * nl / (1.0 + math.sqrt(max(1.0 - 4.0 * k2 * nl * nl, 0.0))), 1.0)
    c = math.sqrt(x2)
    s = math.sqrt(1.0 - x2)
    if nz * nl < 0.0:
        s = -s
    dl, dz = big * math.asin(r * c / big), r * s
    return (dl, dz) if nl * dl + nz * dz >= 0.0 else (-dl, -dz)


@njit
def _deepest(al, az, el, ez, r, big, sl, sz, a_end, b_end):  # type: ignore[no-untyped-def]
    """A segment that enters: the least signed distance along it, ``(d, t, ∂d/∂l, ∂d/∂z)``;
    ``a_end``, ``b_end`` its ends' :func:`inlet_point`. The signed distance of a convex region
    is convex, so its slope along the segment, ``g(t) = ∇d · e``, does not decrease: the least
    is at an end whose slope points inside, else where ``g`` changes sign: by false position
    on ``g`` (Illinois) where it is smooth, and where it jumps (the deepest point on the
    region's medial axis, two sides equally near: ``g`` keeps its value on approach) where
    the tangents of ``d`` at both ends of the bracket meet (they close on the kink
    quadratically); to ``1e-14`` of the length, or a slope that small. The point returned is
    the last one: it moves with the data as smoothly as the root does."""
    lo, hi = 0.0, 1.0
    glo = a_end[1] * el + a_end[2] * ez
    ghi = b_end[1] * el + b_end[2] * ez
    if glo >= 0.0 or ghi <= 0.0:
        return (
            (a_end[0], 0.0, a_end[1], a_end[2])
            if glo >= 0.0
            else (b_end[0], 1.0, b_end[1], b_end[2])
        )
    dlo, dhi, wlo, whi = a_end[0], b_end[0], glo, ghi  # w: the slopes Illinois weighs
    flat = 1e-14 * math.hypot(el, ez)  # a slope this small is the root (to ~1e-14 of it)
    last, side, kink, before = (math.nan, 0.0, 0.0, 0.0), 0, False, -1.0
    for _ in range(BRACKET_STEPS):
        if kink:  # where the tangents at both ends meet
            t = (dhi - dlo + glo * lo - ghi * hi) / (glo - ghi)
        else:  # where the slope, weighed, is 0 (false position)
            t = lo + (hi - lo) * wlo / (wlo - whi)
        if not lo < t < hi:
            t = 0.5 * (lo + hi)
            if not lo < t < hi:  # the bracket is two neighbouring numbers
                break
        d, nl, nz = inlet_point(al + t * el, az + t * ez, r, big, sl, sz)
        last = (d, t, nl, nz)
        g = nl * el + nz * ez
        same = ghi if g > 0.0 else glo  # the slope at the bracket's end on this side
        kink = abs(g - same) < 0.2 * abs(same)  # it did not change coming closer: a jump
        if g > 0.0:
            hi, dhi, ghi, whi = t, d, g, g
            wlo = 0.5 * wlo if side == 1 else glo  # Illinois: the stale end's slope halved
            side = 1
        elif g < 0.0:
            lo, dlo, glo, wlo = t, d, g, g
            whi = 0.5 * whi if side == -1 else ghi
            side = -1
        else:
            break
        if hi - lo < 1e-14 or abs(t - before) < 1e-15 or abs(g) < flat:
            break
        before = t
    return last


@njit
def inlet_segment(al, az, bl, bz, r, big, sl, sz, a_end, b_end):  # type: ignore[no-untyped-def]
    """``(d, t, ∂d/∂l, ∂d/∂z)`` of the segment ``a → b`` (local, as :func:`inlet_point`);
    ``a_end``, ``b_end`` its ends' :func:`inlet_point` where the caller has them (else
    :data:`UNKNOWN`: they are measured).

    The tangent is parallel to ``e = b − a`` where ``cos² φ = X`` solves
    ``k² n_z² X² − X + n_l² = 0`` (``n ⊥ e`` a unit vector, ``k = r/R``): one root in
    [0, 1], two antipodal points, so the outline is convex. Outside it, the segment is closest
    at an end or, at an interior point, to one of those two points. It enters the region if an
    end is inside, or if its line passes between the two points while ``a``'s normal faces
    along ``e`` and ``b``'s against it (the region then lies on the line between them); then
    the deepest point is found where the distance's slope along it changes sign (to 1e-14 of
    the length)."""
    da, nal, naz = a_end if a_end[0] == a_end[0] else inlet_point(al, az, r, big, sl, sz)
    db, nbl, nbz = b_end if b_end[0] == b_end[0] else inlet_point(bl, bz, r, big, sl, sz)
    el, ez = bl - al, bz - az
    res = (da, 0.0, nal, naz) if da <= db else (db, 1.0, nbl, nbz)
    if el * el + ez * ez < _POINT2:
        return res
    length = math.hypot(el, ez)
    if da <= 0.0 or db <= 0.0:
        return _deepest(al, az, el, ez, r, big, sl, sz, (da, nal, naz), (db, nbl, nbz))
    nl, nz = -ez / length, el / length
    cl, cz = _support(nl, nz, r, big)
    ga = el * (cz - az) - ez * (cl - al)  # sides of the line of the two support points
    gb = el * (-cz - az) - ez * (-cl - al)
    if ga * gb < 0.0 and nal * el + naz * ez < 0.0 and nbl * el + nbz * ez > 0.0:
        return _deepest(al, az, el, ez, r, big, sl, sz, (da, nal, naz), (db, nbl, nbz))
    for side in (1.0, -1.0):
        ql, qz = side * cl, side * cz
        t = ((ql - al) * el + (qz - az) * ez) / (length * length)
        if 0.0 < t < 1.0:
            ol, oz = al + t * el - ql, az + t * ez - qz
            d = math.hypot(ol, oz)
            if d < res[0]:  # touching (d <= _ON): the outline's normal there, ±n
                res = (d, t, ol / d, oz / d) if d > _ON else (d, t, side * nl, side * nz)
    return res


@njit
def measure_point(shapes, j, pl, pz):  # type: ignore[no-untyped-def]
    """:func:`inlet_point` of inlet j of ``shapes`` (``data[j] = [l0, z0, r, R]``, its
    outline samples ``vl, vz[start[j]:stop[j]]``, from its centre)."""
    a, b, data = shapes.start[j], shapes.stop[j], shapes.data
    return inlet_point(
        wrap_period(pl - data[j, 0], shapes.period),
        pz - data[j, 1],
        data[j, 2],
        data[j, 3],
        shapes.vl[a:b],
        shapes.vz[a:b],
    )


@njit
def measure_segment(shapes, j, al, az, bl, bz, a_end, b_end):  # type: ignore[no-untyped-def]
    """:func:`inlet_segment` of inlet j of ``shapes``, with its ends' distances where known
    (an end measured at another period's copy of the inlet: unknown)."""
    a, b, data, period = shapes.start[j], shapes.stop[j], shapes.data, shapes.period
    la = wrap_period(al - data[j, 0], period)
    lb = la + wrap_period(bl - al, period)
    if lb != wrap_period(bl - data[j, 0], period):  # b measured at another period's copy
        b_end = UNKNOWN
    return inlet_segment(
        la,
        az - data[j, 1],
        lb,
        bz - data[j, 1],
        data[j, 2],
        data[j, 3],
        shapes.vl[a:b],
        shapes.vz[a:b],
        a_end,
        b_end,
    )


KERNELS = ShapeKernels(measure_point, measure_segment, boxed=True, ends=True)
"""How the compiled measurement measures an inlet (a part far from its box: the box's
distance; a segment's ends measured once)."""
