"""An obstacle with a height: its footprint extruded from the pipe surface up to ``H``.

An obstacle of footprint ``F`` (a shape in the developed view's (l, z) plane) and height ``H``
(m above the pipe surface) is the solid ``{(l, z, h) : (l, z) ∈ F, h ≤ H}`` in DV coordinates;
below the surface is the pipe wall, which the height limits keep every part out of. With
``d₂`` the footprint's signed distance in the plane (negative inside ``F``) and
``d_h = h − H``, a point's signed distance to the solid is

    d = min(max(d₂, d_h), 0) + ‖(max(d₂, 0), max(d_h, 0))‖

:func:`solid`: beside the solid and below its top ``d = d₂``; above its top face ``d = d_h``;
past its top edge ``√(d₂² + d_h²)``; inside ``max(d₂, d_h)``. ``H = ∞`` gives ``d = d₂``, a
wall to the sky (every obstacle without a height). ``d`` is nondecreasing in both ``d₂`` and
``d_h`` and 1-Lipschitz in each, so bounds of ``d₂`` and ``d_h`` over a part give bounds of
``d`` (:mod:`dvqp.geometry.link_pieces`). Its gradient with respect to ``(l, z, h)`` is
``(∂d/∂d₂ · ∇d₂, ∂d/∂d_h)``: the footprint's normal beside it, ``e_h`` above it,
``(d₂ ∇d₂ + d_h e_h)/d`` past the edge. On the edge line (``d₂ = 0 = d_h``) and where
``d₂ = d_h`` inside it is not differentiable; :func:`solid` takes the footprint's side there
(a subgradient), and the exact verification after each step decides.
"""

from __future__ import annotations

import math

from solvers.jit import njit


@njit(inline="always")
def solid(d2, dh):  # type: ignore[no-untyped-def]
    """``(d, ∂d/∂d₂, ∂d/∂d_h)``: the signed distance (m) of a point whose footprint distance is
    ``d2`` and whose height above the solid's top is ``dh`` (m; ``-inf`` for an unbounded
    obstacle: then ``(d2, 1, 0)`` exactly). A NaN ``d2`` stays NaN."""
    if d2 != d2:
        return d2, 0.0, 0.0
    if d2 > 0.0:
        if dh > 0.0:
            r = math.hypot(d2, dh)
            return r, d2 / r, dh / r
        return d2, 1.0, 0.0
    if dh > d2:  # above the top (d₂ ≤ 0 < d_h), or inside nearer the top
        return dh, 0.0, 1.0
    return d2, 1.0, 0.0


@njit(inline="always")
def chord_lowest(a, b, t0, t1):  # type: ignore[no-untyped-def]
    """``(ρ, t)``: the least distance (m) from the pipe axis of the 3-D chord
    ``a + t (b − a)`` over ``t ∈ [t0, t1]`` and where it is. ``ρ(t)`` is convex (the distance
    of a line's points from the axis), so the least is the axis' foot on the chord's xy line,
    clamped into the interval."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    length2 = ex * ex + ey * ey
    t = -(a[0] * ex + a[1] * ey) / length2 if length2 > 0.0 else t0
    t = min(max(t, t0), t1)
    return math.hypot(a[0] + t * ex, a[1] + t * ey), t


@njit(inline="always")
def chord_radial(a, b, t):  # type: ignore[no-untyped-def]
    """``(u_x, u_y)``: the unit xy direction from the pipe axis to the chord's point at ``t``
    (``∂ρ = u · ∂P_xy``; 0 on the axis)."""
    x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
    rho = math.hypot(x, y)
    if rho > 0.0:
        return x / rho, y / rho
    return 0.0, 0.0
