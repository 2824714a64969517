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

A signed distance to an obstacle is 1-Lipschitz, so the true link's clearance is at least the
straight segment's minus ``δ``. dvqp's obstacle dampers, their exact check and its reports
measure the straight DV segment (exact for the developed-view drawing the obstacles are given
in); :func:`link_bends` gives each link's ``δ``, the most by which the real 3-D link can be
closer (``docs/theory.md`` says when that matters). ``δ`` is 0 for a link along the pipe
(``Δφ = 0``) and grows with the angle a link spans and with how unequal its ends' heights are.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.workspace import link_ends


@njit(cache=True)
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
    farthest its true DV image strays from the straight DV segment the obstacle dampers and
    their exact check measure."""
    o, ends = np.asarray(state.origins), link_ends(state.k, state.rail)
    return np.array([state.radius * abs(link_bend(o[a, 0], o[a, 1], o[b, 0], o[b, 1])[0])
                     for a, b in ends])  # fmt: skip
