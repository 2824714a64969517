"""Every guarded link's clearance to every obstacle as the real link's, not the straight DV
segment's (:mod:`dvqp.geometry.bend`): a bound from the link's bend where that suffices, else
measured by halving (:mod:`dvqp.geometry.link_pieces`), with its gradient. To an obstacle
with a height the clearance is the solid's (:mod:`dvqp.geometry.solid`): the whole link as
one piece is bounded below by ``solid(d₂ − δ, h_lo − H)``, ``h_lo`` its chord's lowest
height, and above by the solid's distance at its closest point.
"""

from __future__ import annotations

import math

from dvqp.geometry.bend import PRECISION, link_bend, link_point
from dvqp.geometry.link_pieces import link_clearance
from dvqp.geometry.measure import fill, link_row, point_row
from dvqp.geometry.solid import chord_lowest, chord_radial, solid
from solvers.jit import njit


@njit(separate=True, python=True)  # Python calls it in every plan too
def real_links(shapes, chain, origins, radius, tool, near) -> None:  # type: ignore[no-untyped-def]
    """The clearance of every guarded link's real DV image to every obstacle, into ``near``'s
    ``real_*`` rows: the least over the link's pieces of the straight piece's clearance less
    the piece's ``δ``, its normal, the link parameter of its closest point and the piece.
    ``chain`` (m, 3) the guarded points' DV ``[l, z, h]``, ``origins`` (m, 3) their 3-D
    positions, m; ``tool`` the probe's index among them.

    A pair is cut into pieces only where it matters: where the real link may be below
    ``shapes.refine`` (its damper's margin) or be the closest part of the arm to any obstacle
    (or, the probe's holder, of the probe and its holder: both are reported). Elsewhere, and
    for shapes of your own (no kernels), the whole link is one piece: the straight row less
    the link's ``δ`` (in ``near.bends``), a bound below the truth by at most ``2 δ``, above
    the margin and above the arm's closest part (for an obstacle with a height: the one-piece
    bounds, :func:`_one_piece`, may be as far apart). Rows that the broad phase left at their
    box's bound (beyond ``shapes.far``), or not written (an obstacle it skipped), are measured
    exactly first wherever they may matter."""
    ends, bends = near.ends, near.bends
    for i in range(ends.shape[0]):
        a, b = origins[ends[i, 0]], origins[ends[i, 1]]
        bends[i] = radius * abs(link_bend(a[0], a[1], b[0], b[1])[0])
    arm, probe = _closest(shapes, near, tool, origins, radius)
    if _any_finite(shapes.far):
        arm, probe = _seed(shapes, chain, near, tool, arm, probe, origins, radius)
        arm, probe = _broad(shapes, chain, near, tool, arm, probe, origins, radius)
    for j in range(near.real_distance.shape[0]):
        if shapes.point_at[j] == 0 or near.skipped[j]:
            continue
        for i in range(ends.shape[0]):
            d, reported = near.real_distance[j, i], probe if ends[i, 1] == tool else arm
            gap = _gap(shapes, near, j, i)
            if gap > PRECISION and (d < shapes.refine[j] + gap or d < reported):
                a, b = origins[ends[i, 0]], origins[ends[i, 1]]
                link_clearance(shapes, j, i, a, b, chain[ends[i, 0], 0], radius, near)


@njit(inline="always")
def _any_finite(values) -> bool:  # type: ignore[no-untyped-def]
    """Whether any of ``values`` is finite (a loop: ``np.isfinite(...).any()`` compiles
    numba's ufunc machinery, a second of a cold start)."""
    for i in range(values.shape[0]):  # noqa: SIM110 (a generator compiles slower)
        if math.isfinite(values[i]):
            return True
    return False


@njit
def _closest(shapes, near, tool, origins, radius):  # type: ignore[no-untyped-def]
    """Every link's row as one piece (its straight row less its bend), and ``(arm, probe)``:
    bounds above the clearance of the arm's closest part and of the probe or its holder, over
    the exact rows (those not beyond ``shapes.far``; an obstacle the broad phase skipped has
    none, and its rows are not written)."""
    ends, points = near.ends, near.point_distance
    arm, probe = math.inf, math.inf
    for j in range(near.real_distance.shape[0]):
        far = shapes.far[j]
        if near.skipped[j]:
            continue
        for p in range(points.shape[1]):
            if points[j, p] <= far:
                arm = min(arm, points[j, p])
                probe = min(probe, points[j, p]) if p == tool else probe
        for i in range(ends.shape[0]):
            _one_piece(shapes, near, origins, radius, j, i)
            if near.link_distance[j, i] <= far:
                arm = min(arm, _upper(shapes, near, j, i))
                if ends[i, 1] == tool:
                    probe = min(probe, _upper(shapes, near, j, i))
    return arm, probe


@njit(inline="always")
def _one_piece(shapes, near, origins, radius, j, i) -> None:  # type: ignore[no-untyped-def]
    """Link i's real row to obstacle j as one piece: its straight row less its bend; to an
    obstacle of height ``H``, ``solid(d₂ − δ, h_lo − H)`` (``h_lo`` the chord's lowest
    height), with ``solid(d₂ + δ, h − H)`` at its closest point as its upper bound."""
    nl, nz, t = near.link_normal[j, i, 0], near.link_normal[j, i, 1], near.link_t[j, i]
    height, normal = shapes.height[j], near.real_normal[j, i]
    near.real_at[j, i], near.real_t0[j, i], near.real_t1[j, i] = t, 0.0, 1.0
    if not height < math.inf:
        near.real_distance[j, i] = near.link_distance[j, i] - near.bends[i]
        normal[0], normal[1] = nl, nz
        return
    a, b = origins[near.ends[i, 0]], origins[near.ends[i, 1]]
    rho, low = chord_lowest(a, b, 0.0, 1.0)
    d2, bend = near.link_distance[j, i], near.bends[i]
    d, w2, wh = solid(d2 - bend, rho - radius - height)
    x, y, _ = link_point(a, b, t)
    near.real_distance[j, i] = d
    near.real_upper[j, i] = solid(d2 + bend, math.hypot(x, y) - radius - height)[0]
    normal[0], normal[1], normal[2] = w2 * nl, w2 * nz, wh
    near.real_low[j, i], near.real_footprint[j, i] = low, w2


@njit(inline="always")
def _upper(shapes, near, j, i):  # type: ignore[no-untyped-def]
    """An upper bound (m) of link i's real clearance to obstacle j from its exact one-piece
    row: the straight row plus the bend, or the solid's (:func:`_one_piece`)."""
    if shapes.height[j] < math.inf:
        return near.real_upper[j, i]
    return near.link_distance[j, i] + near.bends[i]


@njit(inline="always")
def _gap(shapes, near, j, i):  # type: ignore[no-untyped-def]
    """How far above its row link i's real clearance to obstacle j may be (m): twice its
    bend, or the solid's bounds' difference."""
    if shapes.height[j] < math.inf:
        return near.real_upper[j, i] - near.real_distance[j, i]
    return 2.0 * near.bends[i]


@njit(inline="always")
def _written(shapes, near, origins, radius, j) -> None:  # type: ignore[no-untyped-def]
    """Obstacle j's rows, if the broad phase skipped it, written at its bound (its real rows
    that less the bend); it stays skipped."""
    if near.skipped[j]:
        fill(near, j)
        for i in range(near.ends.shape[0]):
            _one_piece(shapes, near, origins, radius, j, i)


@njit(inline="always")
def _unskip(shapes, near, origins, radius, j) -> None:  # type: ignore[no-untyped-def]
    """Obstacle j, if the broad phase skipped it, is measured: its bounds become rows."""
    _written(shapes, near, origins, radius, j)
    near.skipped[j] = False


@njit
def _seed(shapes, chain, near, tool, arm, probe, origins, radius):  # type: ignore[no-untyped-def]
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
                d = near.bound[j] if near.skipped[j] else points[j, p]
                if d > shapes.far[j] and d < best:
                    best, bj, bp = d, j, p
        if bj >= 0:
            _unskip(shapes, near, origins, radius, bj)
            point_row(shapes, bj, chain, bp, near, True)
            arm = min(arm, points[bj, bp])
            probe = min(probe, points[bj, bp]) if bp == tool else probe
    return arm, probe


@njit
def _broad(shapes, chain, near, tool, arm, probe, origins, radius):  # type: ignore[no-untyped-def]
    """Measure exactly every row left at its box's bound (beyond ``shapes.far``) that may
    matter: a point whose bound is below the arm's (probe's) closest part, a link whose bound
    less its bend is below that, below ``far`` or may need refining (:func:`real_links`)."""
    ends, bends, points, links = near.ends, near.bends, near.point_distance, near.link_distance
    most = 0.0
    for i in range(bends.shape[0]):
        most = max(most, bends[i])
    for j in range(points.shape[0]):
        far = shapes.far[j]
        if far == math.inf or (
            near.skipped[j]  # one bound in every row: none may matter
            and near.bound[j] - 3.0 * most > max(far, shapes.refine[j], arm, probe)
        ):
            continue
        _written(shapes, near, origins, radius, j)  # its rows: once; one measured unskips it
        for p in range(points.shape[1]):
            if far < points[j, p] < (probe if p == tool else arm):
                near.skipped[j] = False
                point_row(shapes, j, chain, p, near, True)
                arm = min(arm, points[j, p])
                probe = min(probe, points[j, p]) if p == tool else probe
        for i in range(ends.shape[0]):
            d = near.real_distance[j, i]  # the one-piece row of the bound
            reported = probe if ends[i, 1] == tool else arm
            if links[j, i] > far and (
                d <= far or d < shapes.refine[j] + 2.0 * bends[i] or d < reported
            ):
                near.skipped[j] = False
                link_row(shapes, j, chain, i, near, True)
                _one_piece(shapes, near, origins, radius, j, i)
                arm = min(arm, _upper(shapes, near, j, i))
                if ends[i, 1] == tool:
                    probe = min(probe, _upper(shapes, near, j, i))
    return arm, probe


@njit
def _turn(a, b, ja, jb, t, c):  # type: ignore[no-untyped-def]
    """``∂φ/∂Q_c`` (rad/rad) of the link's point at ``t``, ``φ = atan2(y, x)``:
    ``(x ∂y − y ∂x)/ρ²``; ``ja``, ``jb`` the ends' positional Jacobians (rows x, y, z)."""
    x, y, _ = link_point(a, b, t)
    dx = (1.0 - t) * ja[0, c] + t * jb[0, c]
    dy = (1.0 - t) * ja[1, c] + t * jb[1, c]
    return (x * dy - y * dx) / (x * x + y * y)


@njit(separate=True)
def real_link_gradient(near, origins, frame_jacobians, radius, j, i, out) -> None:  # type: ignore[no-untyped-def]
    """``∂d/∂Q`` (m/rad, (n,)) of link i's real clearance to obstacle j (as :func:`real_links`
    measured it) into ``out``: ``n · ∂p/∂Q`` at the closest point ``p`` of its piece, less the
    piece's ``∂δ/∂Q = R sign(g) (∂φ(P(τ)) − (1 − u) ∂φ(P_0) − u ∂φ(P_1))`` at the piece's
    extreme ``u`` (``τ`` on the link): envelopes, the closest point and the extreme held. To
    an obstacle with a height both are the footprint's part (weighted by ``∂d/∂d₂``,
    ``near.real_footprint``), and the height's part adds ``∂d/∂d_h · ∂ρ/∂Q`` at the piece's
    lowest point (``near.real_low``)."""
    ea, eb = near.ends[i, 0], near.ends[i, 1]
    a, b, ja, jb = origins[ea], origins[eb], frame_jacobians[ea], frame_jacobians[eb]
    t0, t1 = near.real_t0[j, i], near.real_t1[j, i]
    s = (near.real_at[j, i] - t0) / (t1 - t0)
    nl, nz, nh = near.real_normal[j, i, 0], near.real_normal[j, i, 1], near.real_normal[j, i, 2]
    x0, y0, _ = link_point(a, b, t0)
    x1, y1, _ = link_point(a, b, t1)
    g, u = link_bend(x0, y0, x1, y1)
    weight = near.real_footprint[j, i] * radius
    sign = weight if g > 0.0 else (-weight if g < 0.0 else 0.0)
    tau = t0 + u * (t1 - t0)
    for c in range(out.shape[0]):
        turn0, turn1 = _turn(a, b, ja, jb, t0, c), _turn(a, b, ja, jb, t1, c)
        z0 = (1.0 - t0) * ja[2, c] + t0 * jb[2, c]
        z1 = (1.0 - t1) * ja[2, c] + t1 * jb[2, c]
        out[c] = nl * radius * ((1.0 - s) * turn0 + s * turn1) + nz * ((1.0 - s) * z0 + s * z1)
        if sign != 0.0:
            out[c] -= sign * (_turn(a, b, ja, jb, tau, c) - (1.0 - u) * turn0 - u * turn1)
    if nh != 0.0:  # ∂ρ/∂Q at the lowest point: the radial direction there
        low = near.real_low[j, i]
        ux, uy = chord_radial(a, b, low)
        for c in range(out.shape[0]):
            jx = (1.0 - low) * ja[0, c] + low * jb[0, c]
            jy = (1.0 - low) * ja[1, c] + low * jb[1, c]
            out[c] += nh * (ux * jx + uy * jy)
