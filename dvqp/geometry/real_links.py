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
dvqp keeps, checks and reports for a link (:func:`real_links`) is the least ``d − δ`` over
pieces found by halving (a piece's ``δ`` shrinks as the square of its length) until the pieces
that may hold the minimum bend by at most ``PRECISION / 2``: never above the real link's
clearance, and below it by at most ``PRECISION``. A link that spans no angle (``Δφ = 0``) is
straight in the DV too.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.measure import OTHER, link_row, point_row, shape_segment
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import link_ends
from solvers.jit import njit

PRECISION = 1e-5
"""m: the most a link's clearance, where measured in pieces, may be below its real one."""
MAX_PIECES = 256
"""Pieces waiting at once in the halving of one link (:func:`real_links`)."""


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
    return np.array([state.radius * abs(link_bend(o[a, 0], o[a, 1], o[b, 0], o[b, 1])[0])
                     for a, b in ends])  # fmt: skip


@njit(inline="always")
def _at(a, b, t):  # type: ignore[no-untyped-def]
    """The point ``a + t (b − a)`` of a 3-D link: ``(x, y, z)``, m."""
    return a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])


@njit
def real_links(shapes, chain, origins, radius, tool, near) -> None:  # type: ignore[no-untyped-def]
    """The clearance of every guarded link's real DV image to every obstacle, into ``near``'s
    ``real_*`` rows: the least over the link's pieces of the straight piece's clearance less
    the piece's ``δ``, its normal, the link parameter of its closest point and the piece.
    ``chain`` (m, 3) the guarded points' DV ``[l, z, h]``, ``origins`` (m, 3) their 3-D
    positions, m; ``tool`` the probe's index among them.

    A pair is cut into pieces only where it matters: where the real link may be below
    ``shapes.refine`` (its damper's margin) or be the closest part of the arm to any obstacle
    (or, the probe's holder, of the probe and its holder: both are reported). Elsewhere, and
    for shapes of your own (:data:`OTHER`), the whole link is one piece: the straight row less
    the link's ``δ`` (in ``near.bends``), a bound below the truth by at most ``2 δ``, above
    the margin and above the arm's closest part. Rows that the broad phase left at their box's
    bound (beyond ``shapes.far``) are measured exactly first wherever they may matter."""
    ends, bends = near.ends, near.bends
    for i in range(ends.shape[0]):
        a, b = origins[ends[i, 0]], origins[ends[i, 1]]
        bends[i] = radius * abs(link_bend(a[0], a[1], b[0], b[1])[0])
    arm, probe = _closest(shapes, near, tool)
    if np.isfinite(shapes.far).any():
        arm, probe = _seed(shapes, chain, near, tool, arm, probe)
        arm, probe = _broad(shapes, chain, near, tool, arm, probe)
    for j in range(near.real_distance.shape[0]):
        if shapes.code[j] == OTHER or near.skipped[j]:
            continue
        for i in range(ends.shape[0]):
            d, reported = near.real_distance[j, i], probe if ends[i, 1] == tool else arm
            if 2.0 * bends[i] > PRECISION and (
                d < shapes.refine[j] + 2.0 * bends[i] or d < reported
            ):
                a, b = origins[ends[i, 0]], origins[ends[i, 1]]
                _pieces(shapes, j, i, a, b, chain[ends[i, 0], 0], radius, near)


@njit
def _closest(shapes, near, tool):  # type: ignore[no-untyped-def]
    """Every link's row as one piece (its straight row less its bend), and ``(arm, probe)``:
    bounds above the clearance of the arm's closest part and of the probe or its holder, over
    the exact rows (those not beyond ``shapes.far``)."""
    ends, bends, points = near.ends, near.bends, near.point_distance
    arm, probe = math.inf, math.inf
    for j in range(near.real_distance.shape[0]):
        far = shapes.far[j]
        for p in range(points.shape[1]):
            if points[j, p] <= far:
                arm = min(arm, points[j, p])
                probe = min(probe, points[j, p]) if p == tool else probe
        for i in range(ends.shape[0]):
            _one_piece(near, j, i)
            if near.link_distance[j, i] <= far:
                arm = min(arm, near.link_distance[j, i] + bends[i])
                if ends[i, 1] == tool:
                    probe = min(probe, near.link_distance[j, i] + bends[i])
    return arm, probe


@njit(inline="always")
def _one_piece(near, j, i) -> None:  # type: ignore[no-untyped-def]
    """Link i's real row to obstacle j as one piece: its straight row less its bend."""
    near.real_distance[j, i] = near.link_distance[j, i] - near.bends[i]
    near.real_normal[j, i, 0] = near.link_normal[j, i, 0]
    near.real_normal[j, i, 1] = near.link_normal[j, i, 1]
    near.real_at[j, i], near.real_t0[j, i], near.real_t1[j, i] = near.link_t[j, i], 0.0, 1.0


@njit(inline="always")
def _unskip(near, j) -> None:  # type: ignore[no-untyped-def]
    """Obstacle j, if the broad phase skipped it, is measured: its bounds become rows."""
    near.skipped[j] = False


@njit
def _seed(shapes, chain, near, tool, arm, probe):  # type: ignore[no-untyped-def]
    """Where no exact row bounds the arm (or the probe): the point row of least box bound
    measured exactly, so that :func:`_broad` has a bound to compare with."""
    points = near.point_distance
    for which in range(2):
        if (arm if which == 0 else probe) < math.inf:
            continue
        best, bj, bp = math.inf, -1, -1
        lo, hi = (0, points.shape[1]) if which == 0 else (tool, tool + 1)
        for j in range(points.shape[0]):
            for p in range(lo, hi):
                if points[j, p] > shapes.far[j] and points[j, p] < best:
                    best, bj, bp = points[j, p], j, p
        if bj >= 0:
            _unskip(near, bj)
            point_row(shapes, bj, chain, bp, near, True)
            arm = min(arm, points[bj, bp])
            probe = min(probe, points[bj, bp]) if bp == tool else probe
    return arm, probe


@njit
def _broad(shapes, chain, near, tool, arm, probe):  # type: ignore[no-untyped-def]
    """Measure exactly every row left at its box's bound (beyond ``shapes.far``) that may
    matter: a point whose bound is below the arm's (probe's) closest part, a link whose bound
    less its bend is below that, below ``far`` or may need refining (:func:`real_links`)."""
    ends, bends, points, links = near.ends, near.bends, near.point_distance, near.link_distance
    most = bends.max() if bends.shape[0] else 0.0
    for j in range(points.shape[0]):
        far = shapes.far[j]
        if far == math.inf or (
            near.skipped[j]  # one bound in every row: none may matter
            and points[j, 0] - 3.0 * most > max(far, shapes.refine[j], arm, probe)
        ):
            continue
        for p in range(points.shape[1]):
            if far < points[j, p] < (probe if p == tool else arm):
                _unskip(near, j)
                point_row(shapes, j, chain, p, near, True)
                arm = min(arm, points[j, p])
                probe = min(probe, points[j, p]) if p == tool else probe
        for i in range(ends.shape[0]):
            d = links[j, i] - bends[i]
            reported = probe if ends[i, 1] == tool else arm
            if links[j, i] > far and (d <= far or d < shapes.refine[j] + 2.0 * bends[i]
                                      or d < reported):  # fmt: skip
                _unskip(near, j)
                link_row(shapes, j, chain, i, near, True)
                _one_piece(near, j, i)
                arm = min(arm, links[j, i] + bends[i])
                if ends[i, 1] == tool:
                    probe = min(probe, links[j, i] + bends[i])
    return arm, probe


@njit
def _piece(shapes, j, a, b, la, radius, t0, t1):  # type: ignore[no-untyped-def]
    """``(d, δ, s, ∂d/∂l, ∂d/∂z)`` of the piece ``[t0, t1]`` of the link ``a → b`` to obstacle
    j: its straight DV piece's clearance, its bend, its closest point's parameter and normal."""
    x0, y0, z0 = _at(a, b, t0)
    x1, y1, z1 = _at(a, b, t1)
    l0 = la + radius * math.atan2(a[0] * y0 - a[1] * x0, a[0] * x0 + a[1] * y0)
    l1 = la + radius * math.atan2(a[0] * y1 - a[1] * x1, a[0] * x1 + a[1] * y1)
    d, s, nl, nz = shape_segment(shapes, j, l0, z0, l1, z1)
    return d, radius * abs(link_bend(x0, y0, x1, y1)[0]), s, nl, nz


@njit
def _pieces(shapes, j, i, a, b, la, radius, near) -> None:  # type: ignore[no-untyped-def]
    """Link i's clearance to obstacle j by halving its pieces, a level at a time (branch and
    bound). Each piece has its straight DV piece's clearance ``d`` and bend ``δ``: its real
    image's clearance lies in ``[d − δ, d + δ]``. A piece bent by at most ``PRECISION / 2`` is
    final (its ``d − δ`` a candidate); another is halved if ``d − δ`` is below both the least
    ``d + δ`` seen and the least candidate, else dropped (it cannot hold the minimum). The
    least candidate is the clearance (a piece that finds no room among ``MAX_PIECES`` is a
    candidate as it is)."""
    live, halves = np.empty((MAX_PIECES, 2)), np.empty((MAX_PIECES, 2))
    out = np.empty((MAX_PIECES, 5))
    live[0, 0], live[0, 1], count, upper, best = 0.0, 1.0, 1, math.inf, math.inf
    while count > 0:
        for p in range(count):
            out[p, 0], out[p, 1], out[p, 2], out[p, 3], out[p, 4] = _piece(
                shapes, j, a, b, la, radius, live[p, 0], live[p, 1])  # fmt: skip
            upper = min(upper, out[p, 0] + out[p, 1])
        for p in range(count):  # the final pieces
            if 2.0 * out[p, 1] <= PRECISION and out[p, 0] - out[p, 1] < best:
                best = _candidate(near, j, i, live[p], out[p])
        n = 0
        for p in range(count):  # the others, halved where they may hold the minimum
            if 2.0 * out[p, 1] > PRECISION and out[p, 0] - out[p, 1] < min(upper, best):
                if n + 2 > MAX_PIECES:
                    if out[p, 0] - out[p, 1] < best:
                        best = _candidate(near, j, i, live[p], out[p])
                    continue
                middle = 0.5 * (live[p, 0] + live[p, 1])
                halves[n, 0], halves[n, 1] = live[p, 0], middle
                halves[n + 1, 0], halves[n + 1, 1] = middle, live[p, 1]
                n += 2
        live, halves, count = halves, live, n


@njit(inline="always")
def _candidate(near, j, i, piece, found):  # type: ignore[no-untyped-def]
    """Write the piece ``[t0, t1]`` with ``(d, δ, s, n_l, n_z)`` as link i's clearance to
    obstacle j; return it, ``d − δ``."""
    t0, t1 = piece[0], piece[1]
    near.real_distance[j, i] = found[0] - found[1]
    near.real_normal[j, i, 0], near.real_normal[j, i, 1] = found[3], found[4]
    near.real_at[j, i] = t0 + found[2] * (t1 - t0)
    near.real_t0[j, i], near.real_t1[j, i] = t0, t1
    return found[0] - found[1]


@njit(inline="always")
def _turn(a, b, ja, jb, t, c):  # type: ignore[no-untyped-def]
    """``∂φ/∂Q_c`` (rad/rad) of the link's point at ``t``, ``φ = atan2(y, x)``:
    ``(x ∂y − y ∂x)/ρ²``; ``ja``, ``jb`` the ends' positional Jacobians (rows x, y, z)."""
    x, y, _ = _at(a, b, t)
    dx = (1.0 - t) * ja[0, c] + t * jb[0, c]
    dy = (1.0 - t) * ja[1, c] + t * jb[1, c]
    return (x * dy - y * dx) / (x * x + y * y)


@njit
def real_link_gradient(near, origins, frame_jacobians, radius, j, i, out) -> None:  # type: ignore[no-untyped-def]
    """``∂d/∂Q`` (m/rad, (n,)) of link i's real clearance to obstacle j (as :func:`real_links`
    measured it) into ``out``: ``n · ∂p/∂Q`` at the closest point ``p`` of its piece, less the
    piece's ``∂δ/∂Q = R sign(g) (∂φ(P(τ)) − (1 − u) ∂φ(P_0) − u ∂φ(P_1))`` at the piece's
    extreme ``u`` (``τ`` on the link): envelopes, the closest point and the extreme held."""
    ea, eb = near.ends[i, 0], near.ends[i, 1]
    a, b, ja, jb = origins[ea], origins[eb], frame_jacobians[ea], frame_jacobians[eb]
    t0, t1 = near.real_t0[j, i], near.real_t1[j, i]
    s = (near.real_at[j, i] - t0) / (t1 - t0)
    nl, nz = near.real_normal[j, i, 0], near.real_normal[j, i, 1]
    x0, y0, _ = _at(a, b, t0)
    x1, y1, _ = _at(a, b, t1)
    g, u = link_bend(x0, y0, x1, y1)
    sign = radius if g > 0.0 else (-radius if g < 0.0 else 0.0)
    tau = t0 + u * (t1 - t0)
    for c in range(out.shape[0]):
        turn0, turn1 = _turn(a, b, ja, jb, t0, c), _turn(a, b, ja, jb, t1, c)
        z0 = (1.0 - t0) * ja[2, c] + t0 * jb[2, c]
        z1 = (1.0 - t1) * ja[2, c] + t1 * jb[2, c]
        out[c] = nl * radius * ((1.0 - s) * turn0 + s * turn1) + nz * ((1.0 - s) * z0 + s * z1)
        if sign != 0.0:
            out[c] -= sign * (_turn(a, b, ja, jb, tau, c) - (1.0 - u) * turn0 - u * turn1)
