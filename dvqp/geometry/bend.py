"""How far a link's true developed-view image strays from the straight DV segment.

A link is a straight 3-D segment ``P(t) = A + t (B − A)``, ``t ∈ [0, 1]``. Its DV image is not
straight: ``z`` is linear in ``t`` (``z(t) = z_A + t Δz``) but ``l = R θ(t)``, with ``θ`` the
angle of ``P(t)`` around the pipe axis, is not. In the frame of ``A``'s angle, with ``ρ_A``,
``ρ_B`` the distances from the axis and ``Δφ`` the angle from ``A`` to ``B``,

    θ(t) = atan2(t c, ρ_A² + t d),   c = ρ_A ρ_B sin Δφ,   d = ρ_A ρ_B cos Δφ − ρ_A².

The straight DV segment's point at the same ``t`` is ``(l_A + R t Δφ, z(t))``, so every point
of the true image lies within ``δ = R max_t |θ(t) − t Δφ|`` of the straight segment. The
extremes of ``g(t) = θ(t) − t Δφ`` (zero at both ends) are where ``θ'(t) = Δφ``:

    (d² + c²) t² + 2 ρ_A² d t + ρ_A⁴ − ρ_A² c / Δφ = 0.

A signed distance to an obstacle is 1-Lipschitz, so a piece of the link keeps a clearance
within its own ``δ`` of its straight DV piece's ``d``: in ``[d − δ, d + δ]``. The clearance
dvqp keeps, checks and reports for a link (:func:`~dvqp.geometry.real_links.real_links`) is
the least ``d − δ`` over pieces found by halving (a piece's ``δ`` shrinks as the square of its
length; :mod:`dvqp.geometry.link_pieces`) until the pieces that may hold the minimum bend by
at most ``PRECISION / 2``: never above the real link's clearance, and below it by at most
``PRECISION``. A link that spans no angle (``Δφ = 0``) is straight in the DV too.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.workspace import link_ends
from solvers.jit import njit

PRECISION = 1e-5
"""m: the most a link's clearance, where measured in pieces, may be below its real one."""


@njit
def link_bend(ax, ay, bx, by):  # type: ignore[no-untyped-def]
    """``(g, t)``: the signed largest ``g(t) = θ(t) − t Δφ`` (rad) of the link from
    ``(ax, ay)`` to ``(bx, by)`` (the xy parts of its ends, m) and where it is (``t`` in
    (0, 1); ``(0.0, 0.0)`` for a link that spans no angle). ``δ = R |g|``."""
    ra2 = ax * ax + ay * ay
    cross, dot = ax * by - ay * bx, ax * bx + ay * by
    phi = math.atan2(cross, dot)
    if phi == 0.0 or ra2 == 0.0:
        return 0.0, 0.0
    c, d = cross, dot - ra2  # ρ_A ρ_B sin Δφ and ρ_A ρ_B cos Δφ − ρ_A²
    qa, qb, qc = d * d + c * c, 2.0 * ra2 * d, ra2 * ra2 - ra2 * c / phi
    worst, at = 0.0, 0.0
    disc = qb * qb - 4.0 * qa * qc
    if qa > 0.0 and disc >= 0.0:
        root = math.sqrt(disc)
        for t in ((-qb - root) / (2.0 * qa), (-qb + root) / (2.0 * qa)):
            if 0.0 < t < 1.0:
                g = math.atan2(t * c, ra2 + t * d) - t * phi
                if abs(g) > abs(worst):
                    worst, at = g, t
    return worst, at


def link_bends(state: KinematicState) -> NDArray[np.float64]:
    """``δ`` (m) of each guarded link of ``state`` (L,), in :func:`link_ends` order: the
    farthest its real DV image strays from its straight DV segment."""
    o, ends = np.asarray(state.origins), link_ends(state.k, state.rail)
    return np.array(
        [state.radius * abs(link_bend(o[a, 0], o[a, 1], o[b, 0], o[b, 1])[0]) for a, b in ends]
    )


@njit(inline="always")
def link_point(a, b, t):  # type: ignore[no-untyped-def]
    """The point ``a + t (b − a)`` of a 3-D link: ``(x, y, z)``, m."""
    return a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])
