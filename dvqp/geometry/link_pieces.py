"""A link's clearance to one obstacle, by halving it into pieces (branch and bound).

Each piece ``[t0, t1]`` of a link has the footprint clearance ``d`` of its straight DV piece
(between the real image's points at ``t0`` and ``t1``) and its bend ``δ``
(:mod:`dvqp.geometry.bend`): the real image's footprint clearance there lies in
``[d − δ, d + δ]``. For an obstacle with a height the piece's clearance to the solid
(:mod:`dvqp.geometry.solid`) lies in ``[solid(d − δ, h_lo − H), U]``, ``h_lo`` the piece's
lowest height (its chord's least distance from the pipe axis, less the pipe's radius) and
``U`` the solid's distance at a point of the piece (its closest point's bound, and its
lowest point's exact one): the bounds meet as the pieces shrink. :func:`link_clearance`
halves the pieces that may hold the least until each one's bounds are within ``PRECISION``
(the bend alone, ``2 δ``, for an unbounded obstacle).

:func:`straight_solids` does the same along the straight DV segment between a link's ends,
its height linear between theirs (no bend): the objective's repulsion of a link from an
obstacle with a height.
"""

from __future__ import annotations

import math

import numpy as np

from dvqp.geometry.bend import PRECISION, link_bend, link_point
from dvqp.geometry.measure import shape_point, shape_segment
from dvqp.geometry.shapes.shape import UNKNOWN
from dvqp.geometry.solid import chord_lowest, solid
from dvqp.kinematics.developed_view import wrap_period
from solvers.jit import njit

MAX_PIECES = 256
"""Pieces waiting at once in the halving of one link (:func:`link_clearance`)."""
SEED_SHORTER = 0.7
"""How much shorter than the square-law estimate the first piece round the straight link's
closest point is cut (its bend must fall within ``PRECISION / 2``: it is not quite square)."""
T0, T1, END0, END1, WIDTH = 0, 1, 2, 7, 12
"""Columns of a piece: its parameters ``t0``, ``t1`` and its ends' ``(l, z, d, n_l, n_z)``
(the image's point there and its footprint distance to the obstacle, or ``d = nan``: not
taken)."""
LB, UB, FINAL, AT, LOW, W2, WH, NL, NZ, DROP, BOUNDS = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10
"""Columns of a piece's bounds (:func:`_bounds`): its clearance's lower and upper bounds, whether
they are close enough (1.0), the link parameters of its footprint's closest point and of its
lowest point, ``∂d/∂d₂`` and ``∂d/∂d_h`` at the lower bound, the footprint's normal, and a
lower bound that only decides whether the piece is dropped (:func:`_supported`)."""


@njit(inline="always")
def _image(a, b, la, radius, t, straight, period):  # type: ignore[no-untyped-def]
    """``(l, z)`` of the link's image at ``t``: the real link's (``a``, ``b`` its 3-D ends,
    ``l`` unwrapped from ``la``), or the straight DV segment's (``a``, ``b`` its DV ends)."""
    if straight:
        return la + t * wrap_period(b[0] - a[0], period), a[1] + t * (b[1] - a[1])
    x, y, z = link_point(a, b, t)
    return la + radius * math.atan2(a[0] * y - a[1] * x, a[0] * x + a[1] * y), z


@njit(inline="always")
def _height(a, b, radius, t, straight):  # type: ignore[no-untyped-def]
    """The image's height at ``t`` (m): linear along a straight segment, the chord's distance
    from the pipe axis less the pipe's radius along a real link."""
    if straight:
        return a[2] + t * (b[2] - a[2]) if a[2] != b[2] else a[2]  # (-inf: a footprint)
    x, y, _ = link_point(a, b, t)
    return math.hypot(x, y) - radius


@njit
def _end(shapes, j, a, b, la, radius, t, piece, col, straight):  # type: ignore[no-untyped-def]
    """The image's point at ``t`` into ``piece[col : col + 5]``, with its distance to
    obstacle j where a segment's distance uses it (an inlet's: no second measurement of a
    shared end)."""
    pl, pz = _image(a, b, la, radius, t, straight, shapes.period)
    piece[col], piece[col + 1] = pl, pz
    d, nl, nz = UNKNOWN
    if shapes.ends[j]:
        d, nl, nz = shape_point(shapes, j, pl, pz)
    piece[col + 2], piece[col + 3], piece[col + 4] = d, nl, nz


@njit
def _copy_end(source, col, target, to) -> None:  # type: ignore[no-untyped-def]
    for c in range(5):
        target[to + c] = source[col + c]


@njit
def _piece(shapes, j, a, b, radius, piece, straight):  # type: ignore[no-untyped-def]
    """``(d, δ, s, ∂d/∂l, ∂d/∂z)`` of a piece of the link to obstacle j: its straight DV
    piece's footprint clearance, its bend (0 along a straight segment), its closest point's
    parameter and normal."""
    d, s, nl, nz = shape_segment(
        shapes,
        j,
        piece[END0],
        piece[END0 + 1],
        piece[END1],
        piece[END1 + 1],
        (piece[END0 + 2], piece[END0 + 3], piece[END0 + 4]),
        (piece[END1 + 2], piece[END1 + 3], piece[END1 + 4]),
    )
    if straight:
        return d, 0.0, s, nl, nz
    x0, y0, _ = link_point(a, b, piece[T0])
    x1, y1, _ = link_point(a, b, piece[T1])
    return d, radius * abs(link_bend(x0, y0, x1, y1)[0]), s, nl, nz


@njit(inline="always")
def _lowest(a, b, t0, t1, radius, straight):  # type: ignore[no-untyped-def]
    """``(h, t)``: the least height (m) of the image over ``[t0, t1]`` and where it is: a
    straight segment's at its lower end, a real link's at its chord's point nearest the pipe
    axis (:func:`~dvqp.geometry.solid.chord_lowest`)."""
    if straight:
        h0, h1 = _height(a, b, radius, t0, True), _height(a, b, radius, t1, True)
        return (h0, t0) if h0 <= h1 else (h1, t1)
    rho, t = chord_lowest(a, b, t0, t1)
    return rho - radius, t


@njit
def _bounds(shapes, j, a, b, la, radius, piece, straight, out) -> None:  # type: ignore[no-untyped-def]
    """A piece's bounds into ``out`` (columns :data:`LB` … :data:`NZ`): ``d ∓ δ`` of its
    footprint clearance (final once ``2 δ ≤ PRECISION``) for an unbounded obstacle; for one of
    height ``H``, ``solid(d − δ, h_lo − H)`` below and the least of the solid's distance at its
    closest point (``solid(d + δ, h − H)``) and at its lowest point (measured) above, final
    once they are within ``PRECISION``."""
    t0, t1 = piece[T0], piece[T1]
    d, bend, s, nl, nz = _piece(shapes, j, a, b, radius, piece, straight)
    at = t0 + s * (t1 - t0)
    out[AT], out[NL], out[NZ] = at, nl, nz
    height = shapes.height[j]
    if not height < math.inf:
        out[LB], out[UB], out[FINAL] = d - bend, d + bend, 1.0 if 2.0 * bend <= PRECISION else 0.0
        out[LOW], out[W2], out[WH], out[DROP] = at, 1.0, 0.0, d - bend
        return
    low, t_low = _lowest(a, b, t0, t1, radius, straight)
    lower, w2, wh = solid(d - bend, low - height)
    upper = solid(d + bend, _height(a, b, radius, at, straight) - height)[0]
    if upper - lower > PRECISION:  # the lowest point's own distance may be closer
        pl, pz = _image(a, b, la, radius, t_low, straight, shapes.period)
        upper = min(upper, solid(shape_point(shapes, j, pl, pz)[0], low - height)[0])
    out[LB], out[UB], out[FINAL] = lower, upper, 1.0 if upper - lower <= PRECISION else 0.0
    out[LOW], out[W2], out[WH], out[DROP] = t_low, w2, wh, lower
    if upper - lower > PRECISION and shapes.convex[j]:
        out[DROP] = max(lower, _supported(shapes, j, a, b, la, radius, piece, straight) - bend)


@njit
def _supported(shapes, j, a, b, la, radius, piece, straight):  # type: ignore[no-untyped-def]
    """A lower bound (m) of ``g(t) = solid(d₂(t), h(t) − H)`` over the piece, ``d₂`` the
    footprint's distance along its straight DV piece and ``h`` its height: the least of the
    greater of ``g``'s tangent lines at the piece's ends. For a convex footprint ``g`` is
    convex (the solid's signed distance is convex and nondecreasing in ``h``, ``(l, z)`` is
    affine along the piece and ``h`` convex: linear, or a chord's distance from the pipe axis),
    so its tangents lie below it: the bound is exact at a kink and its gap shrinks as the
    square of the piece, where :func:`_bounds`' lower bound (the footprint's least distance
    and the least height, from two points) shrinks only as the piece. The real image is
    within the piece's bend of the straight piece (the caller subtracts it)."""
    t0, t1, height = piece[T0], piece[T1], shapes.height[j]
    span = t1 - t0
    dl, dz = (piece[END1] - piece[END0]) / span, (piece[END1 + 1] - piece[END0 + 1]) / span
    g0, s0 = _tangent(shapes, j, a, b, radius, piece, END0, t0, dl, dz, height, straight)
    g1, s1 = _tangent(shapes, j, a, b, radius, piece, END1, t1, dl, dz, height, straight)
    if s0 >= 0.0:
        least = g0
    elif s1 <= 0.0:
        least = g1
    else:  # where the two tangents meet, in [t0, t1]
        t = (g1 - g0 + s0 * t0 - s1 * t1) / (s0 - s1)
        least = g0 + s0 * (min(max(t, t0), t1) - t0)
    return least if least == least else -math.inf  # NaN (a footprint's h = −∞): no bound


@njit(inline="always")
def _tangent(shapes, j, a, b, radius, piece, col, t, dl, dz, height, straight):  # type: ignore[no-untyped-def]
    """``(g, g')`` at an end of the piece (:func:`_supported`), ``g'`` per unit of ``t``; the
    end's footprint distance as :func:`_end` measured it, where it did."""
    d, nl, nz = piece[col + 2], piece[col + 3], piece[col + 4]
    if d != d:
        d, nl, nz = shape_point(shapes, j, piece[col], piece[col + 1])
    if straight:
        h, dh = _height(a, b, radius, t, True), b[2] - a[2]
    else:
        x, y, _ = link_point(a, b, t)
        rho = math.hypot(x, y)
        h = rho - radius
        dh = (x * (b[0] - a[0]) + y * (b[1] - a[1])) / rho if rho > 0.0 else 0.0
    g, w2, wh = solid(d, h - height)
    return g, w2 * (nl * dl + nz * dz) + wh * dh


@njit
def _halving(shapes, j, a, b, la, radius, t, bend, straight, best_piece, found):  # type: ignore[no-untyped-def]
    """The link's clearance to obstacle j by halving its pieces a level at a time from
    :func:`_first_pieces` (``t`` the straight link's closest point, ``bend`` its whole bend):
    the piece that has it into ``best_piece`` and its bounds into ``found``. A final piece is
    a candidate (its lower bound); another is halved if its lower bound is below both the
    least upper bound seen and the least candidate, else dropped (it cannot hold the minimum).
    The least candidate is the clearance (a piece that finds no room among ``MAX_PIECES`` is a
    candidate as it is)."""
    live, halves = np.empty((MAX_PIECES, WIDTH)), np.empty((MAX_PIECES, WIDTH))
    out = np.empty((MAX_PIECES, BOUNDS))
    count = _first_pieces(shapes, j, a, b, la, radius, t, bend, live, straight)
    upper, best = math.inf, math.inf
    while count > 0:
        for p in range(count):
            _bounds(shapes, j, a, b, la, radius, live[p], straight, out[p])
            upper = min(upper, out[p, UB])
        for p in range(count):  # the final pieces
            if out[p, FINAL] != 0.0 and out[p, LB] < best:
                best = _candidate(live[p], out[p], best_piece, found)
        n = 0
        for p in range(count):  # the others, halved where they may hold the minimum
            if out[p, FINAL] == 0.0 and out[p, DROP] < min(upper, best):
                if n + 2 > MAX_PIECES:
                    if out[p, LB] < best:
                        best = _candidate(live[p], out[p], best_piece, found)
                    continue
                _halve(shapes, j, a, b, la, radius, live[p], halves[n], halves[n + 1], straight)
                n += 2
        live, halves, count = halves, live, n


@njit(separate=True)
def link_clearance(shapes, j, i, a, b, la, radius, near) -> None:  # type: ignore[no-untyped-def]
    """Link i's clearance to obstacle j (its ends ``a``, ``b`` in 3-D, m; ``la`` the DV ``l``
    of ``a``) into ``near``'s ``real_*`` rows, by :func:`_halving` its real DV image."""
    piece, found = np.empty(WIDTH), np.empty(BOUNDS)
    _halving(shapes, j, a, b, la, radius, near.link_t[j, i], near.bends[i], False, piece, found)
    near.real_distance[j, i], near.real_upper[j, i] = found[LB], found[UB]
    w2 = found[W2]
    normal = near.real_normal[j, i]
    normal[0], normal[1], normal[2] = w2 * found[NL], w2 * found[NZ], found[WH]
    near.real_at[j, i], near.real_low[j, i], near.real_footprint[j, i] = found[AT], found[LOW], w2
    near.real_t0[j, i], near.real_t1[j, i] = piece[T0], piece[T1]


@njit(separate=True)
def straight_solids(shapes, chain, near) -> None:  # type: ignore[no-untyped-def]
    """Every link's straight DV segment's clearance to every obstacle with a height into
    ``near``'s ``straight_*`` rows, its height linear between its ends' (``chain`` (m, 3), the
    guarded points' DV ``[l, z, h]``): the objective's repulsion. A segment that the
    footprint's row and its lower end's height place outside (``solid(d₂, h_lo − H) > 0``)
    keeps that bound (it adds no repulsion); one that may be inside is halved
    (:func:`_halving`, no bend) where the obstacle's kind is compiled. An obstacle the broad
    phase skipped is left alone, as the penalties leave it."""
    ends, piece, found = near.ends, np.empty(WIDTH), np.empty(BOUNDS)
    for j in range(near.link_distance.shape[0]):
        height = shapes.height[j]
        if not height < math.inf or near.skipped[j]:
            continue
        for i in range(ends.shape[0]):
            a, b = chain[ends[i, 0]], chain[ends[i, 1]]
            t_low = 0.0 if a[2] <= b[2] else 1.0
            d, w2, wh = solid(near.link_distance[j, i], min(a[2], b[2]) - height)
            nl, nz, t = near.link_normal[j, i, 0], near.link_normal[j, i, 1], near.link_t[j, i]
            if d <= 0.0 and shapes.point_at[j] != 0:
                _halving(shapes, j, a, b, a[0], 0.0, t, 0.0, True, piece, found)
                d, w2, wh, nl, nz = found[LB], found[W2], found[WH], found[NL], found[NZ]
                t, t_low = found[AT], found[LOW]
            near.straight_distance[j, i] = d
            normal = near.straight_normal[j, i]
            normal[0], normal[1], normal[2] = w2 * nl, w2 * nz, wh
            near.straight_at[j, i, 0], near.straight_at[j, i, 1] = t, t_low


@njit(inline="always")
def _halve(shapes, j, a, b, la, radius, piece, first, second, straight) -> None:  # type: ignore[no-untyped-def]
    """Cut ``piece`` at its middle into ``first`` and ``second`` (the middle measured once)."""
    middle = 0.5 * (piece[T0] + piece[T1])
    first[T0], first[T1], second[T0], second[T1] = piece[T0], middle, middle, piece[T1]
    _copy_end(piece, END0, first, END0)
    _end(shapes, j, a, b, la, radius, middle, first, END1, straight)
    _copy_end(first, END1, second, END0)
    _copy_end(piece, END1, second, END1)


@njit(inline="always")
def _first_pieces(shapes, j, a, b, la, radius, t, bend, live, straight):  # type: ignore[no-untyped-def]
    """The pieces the halving starts from, into ``live``; returns their count. A piece's bend
    shrinks about as the square of its length: the piece holding ``t`` (where the straight link
    is closest) is cut short enough to be final at once, with a piece as short either side of
    it (the minimum may lie just across a cut, and a long piece next to it could not be
    dropped); the rest of the link is two pieces that the halving drops, or cuts where they
    may hold the minimum (a link without bend is one piece). Every cut is a halving's (at
    ``k / 2ⁿ``): the pieces do not move with the link, so the clearance measured on one has
    the gradient :func:`~dvqp.geometry.real_links.real_link_gradient` gives it."""
    cuts = 1.0
    if bend > 0.0:
        width = SEED_SHORTER * math.sqrt(0.5 * PRECISION / bend)
        cuts = 2.0 ** max(math.ceil(-math.log2(width)), 0) if width < 1.0 else 1.0
    at = min(math.floor(t * cuts), cuts - 1.0)
    count, t0 = 0, 0.0
    for k in range(5):  # the cuts (at − 1, at, at + 1, at + 2) / cuts, then 1
        t1 = min(max((at - 1.0 + k) / cuts, 0.0), 1.0) if k < 4 else 1.0
        if t1 > t0:
            piece = live[count]
            piece[T0], piece[T1] = t0, t1
            if count == 0:
                _end(shapes, j, a, b, la, radius, t0, piece, END0, straight)
            else:
                _copy_end(live[count - 1], END1, piece, END0)
            _end(shapes, j, a, b, la, radius, t1, piece, END1, straight)
            count += 1
            t0 = t1
    return count


@njit(inline="always")
def _candidate(piece, bounds, best_piece, found):  # type: ignore[no-untyped-def]
    """Hold the piece and its bounds as the link's clearance; return its lower bound."""
    for c in range(WIDTH):
        best_piece[c] = piece[c]
    for c in range(BOUNDS):
        found[c] = bounds[c]
    return bounds[LB]
