"""A link's real clearance to one obstacle, by halving it into pieces (branch and bound).

Each piece ``[t0, t1]`` of a link has the clearance ``d`` of its straight DV piece (between
the real image's points at ``t0`` and ``t1``) and its bend ``δ`` (:mod:`dvqp.geometry.bend`):
the real image's clearance there lies in ``[d − δ, d + δ]``. :func:`link_clearance` halves
the pieces that may hold the least until they bend by at most ``PRECISION / 2``.
"""

from __future__ import annotations

import math

import numpy as np

from dvqp.geometry.bend import PRECISION, link_bend, link_point
from dvqp.geometry.measure import shape_point, shape_segment
from dvqp.geometry.shapes.shape import UNKNOWN
from solvers.jit import njit

MAX_PIECES = 256
"""Pieces waiting at once in the halving of one link (:func:`link_clearance`)."""
SEED_SHORTER = 0.7
"""How much shorter than the square-law estimate the first piece round the straight link's
closest point is cut (its bend must fall within ``PRECISION / 2``: it is not quite square)."""
T0, T1, END0, END1, WIDTH = 0, 1, 2, 7, 12
"""Columns of a piece: its parameters ``t0``, ``t1`` and its ends' ``(l, z, d, n_l, n_z)``
(the real image's point there and its distance to the obstacle, or ``d = nan``: not taken)."""


@njit
def _end(shapes, j, a, b, la, radius, t, piece, col):  # type: ignore[no-untyped-def]
    """The real image's point at ``t`` of the link ``a → b`` (``l`` unwrapped from ``la``)
    into ``piece[col : col + 5]``, with its distance to obstacle j where a segment's distance
    uses it (an inlet's: no second measurement of a shared end)."""
    x, y, z = link_point(a, b, t)
    piece[col] = la + radius * math.atan2(a[0] * y - a[1] * x, a[0] * x + a[1] * y)
    piece[col + 1] = z
    d, nl, nz = UNKNOWN
    if shapes.ends[j]:
        d, nl, nz = shape_point(shapes, j, piece[col], z)
    piece[col + 2], piece[col + 3], piece[col + 4] = d, nl, nz


@njit
def _copy_end(source, col, target, to) -> None:  # type: ignore[no-untyped-def]
    for c in range(5):
        target[to + c] = source[col + c]


@njit
def _piece(shapes, j, a, b, radius, piece):  # type: ignore[no-untyped-def]
    """``(d, δ, s, ∂d/∂l, ∂d/∂z)`` of a piece of the link ``a → b`` to obstacle j: its
    straight DV piece's clearance, its bend, its closest point's parameter and normal."""
    x0, y0, _ = link_point(a, b, piece[T0])
    x1, y1, _ = link_point(a, b, piece[T1])
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
    return d, radius * abs(link_bend(x0, y0, x1, y1)[0]), s, nl, nz


@njit(separate=True)
def link_clearance(shapes, j, i, a, b, la, radius, near) -> None:  # type: ignore[no-untyped-def]
    """Link i's clearance to obstacle j (its ends ``a``, ``b`` in 3-D, m; ``la`` the DV ``l``
    of ``a``) into ``near``'s ``real_*`` rows, by halving its pieces a level at a time from
    :func:`_first_pieces`. A piece bent by at most ``PRECISION / 2`` is final (its ``d − δ`` a
    candidate); another is halved if ``d − δ`` is below both the least ``d + δ`` seen and the
    least candidate, else dropped (it cannot hold the minimum). The least candidate is the
    clearance (a piece that finds no room among ``MAX_PIECES`` is a candidate as it is)."""
    live, halves = np.empty((MAX_PIECES, WIDTH)), np.empty((MAX_PIECES, WIDTH))
    out = np.empty((MAX_PIECES, 5))
    count = _first_pieces(shapes, j, a, b, la, radius, near.link_t[j, i], near.bends[i], live)
    upper, best = math.inf, math.inf
    while count > 0:
        for p in range(count):
            out[p, 0], out[p, 1], out[p, 2], out[p, 3], out[p, 4] = _piece(
                shapes, j, a, b, radius, live[p]
            )
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
                _halve(shapes, j, a, b, la, radius, live[p], halves[n], halves[n + 1])
                n += 2
        live, halves, count = halves, live, n


@njit(inline="always")
def _halve(shapes, j, a, b, la, radius, piece, first, second) -> None:  # type: ignore[no-untyped-def]
    """Cut ``piece`` at its middle into ``first`` and ``second`` (the middle measured once)."""
    middle = 0.5 * (piece[T0] + piece[T1])
    first[T0], first[T1], second[T0], second[T1] = piece[T0], middle, middle, piece[T1]
    _copy_end(piece, END0, first, END0)
    _end(shapes, j, a, b, la, radius, middle, first, END1)
    _copy_end(first, END1, second, END0)
    _copy_end(piece, END1, second, END1)


@njit(inline="always")
def _first_pieces(shapes, j, a, b, la, radius, t, bend, live):  # type: ignore[no-untyped-def]
    """The pieces the halving starts from, into ``live``; returns their count. A piece's bend
    shrinks about as the square of its length: the piece holding ``t`` (where the straight link
    is closest) is cut short enough to be final at once, with a piece as short either side of
    it (the minimum may lie just across a cut, and a long piece next to it could not be
    dropped); the rest of the link is two pieces that the halving drops, or cuts where they
    may hold the minimum. Every cut is a halving's (at ``k / 2ⁿ``): the pieces do not move
    with the link, so the clearance measured on one has the gradient
    :func:`~dvqp.geometry.real_links.real_link_gradient` gives it."""
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
                _end(shapes, j, a, b, la, radius, t0, piece, END0)
            else:
                _copy_end(live[count - 1], END1, piece, END0)
            _end(shapes, j, a, b, la, radius, t1, piece, END1)
            count += 1
            t0 = t1
    return count


@njit(inline="always")
def _candidate(near, j, i, piece, found):  # type: ignore[no-untyped-def]
    """Write the piece with ``(d, δ, s, n_l, n_z)`` as link i's clearance to obstacle j;
    return it, ``d − δ``."""
    t0, t1 = piece[T0], piece[T1]
    near.real_distance[j, i] = found[0] - found[1]
    near.real_normal[j, i, 0], near.real_normal[j, i, 1] = found[3], found[4]
    near.real_at[j, i] = t0 + found[2] * (t1 - t0)
    near.real_t0[j, i], near.real_t1[j, i] = t0, t1
    return found[0] - found[1]
