"""How far a run's tool strayed from its path: the distance of each sample to a polyline.

:func:`path_deviation` finds, for every sample, the nearest of the path's segments exactly,
in time about linear in the run's length (it compared every sample with every segment: the
saddle weld at h = 9.9, 52 000 of each, took 110 s; now well under a second). A tree of boxes
around runs of consecutive segments (a path's consecutive segments lie side by side, so their
boxes are tight) is searched for all samples at once, level by level, keeping only the boxes
that could hold a segment nearer than one already known, the segment whose midpoint is
nearest (:class:`scipy.spatial.cKDTree`). Each distance is computed as the all-pairs
comparison computes it, so the result is the same to the last bit.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

LEAF = 16
"""Consecutive segments under one leaf box of the tree."""
BATCH = 4096
"""Samples searched together (bounds the search's temporary arrays)."""
SLACK = 1e-9
"""Relative slack of the box pruning, far above rounding: no box holding the nearest segment
is ever dropped."""


def path_deviation(reference: Array, tool: Array) -> Array:
    """How far each tool position is from the path, m, shape (M,): the distance in
    ``(l, z, h)`` from ``tool[:, :3]`` (M, 4) to the polyline through ``reference[:, :3]``
    (N+1, 4), both with l unwrapped from the same start (as a run and its reference are).

    Exact (the nearest segment of all, each distance computed as :func:`segment_distances`
    does); NaN for a non-finite tool position. The work per sample does not grow with a
    run's length (``O(M log N)`` for a path that does not pass the same place many times);
    where many segments are about as far from a sample (a curve seen from off it) it grows as
    the root of their number, which a finer sampling of the same curve raises.
    """
    start, step = reference[:-1, :3], np.diff(reference[:, :3], axis=0)
    if start.shape[0] == 0:
        start, step = reference[:1, :3], np.zeros((1, 3))
    points = np.asarray(tool, dtype=np.float64)[:, :3]
    out = np.full(points.shape[0], np.nan)
    finite = np.flatnonzero(np.isfinite(points).all(axis=1))
    if finite.size:
        tree = _Boxes(np.ascontiguousarray(start), np.ascontiguousarray(step))
        for s in range(0, finite.size, BATCH):
            rows = finite[s : s + BATCH]
            out[rows] = tree.nearest(points[rows])
    return out


def segment_distances(points: Array, start: Array, step: Array) -> Array:
    """The distance of each point ``points[i]`` (K, 3) to the segment from ``start[i]`` along
    ``step[i]`` (each (K, 3)); a zero-length segment is its point."""
    length2 = np.einsum("ij,ij->i", step, step)
    safe = np.where(length2 > 0.0, length2, 1.0)
    p = points - start
    along = np.clip(np.einsum("ij,ij->i", p, step) / safe, 0.0, 1.0)
    p -= along[:, None] * step
    return np.sqrt(np.einsum("ij,ij->i", p, p))


class _Boxes:
    """The segments ``start + [0, 1] step`` in leaves of :data:`LEAF` consecutive ones, with
    a binary tree of axis-aligned boxes over the leaves (level 0: the leaves' boxes, each
    level up one box for two) and the segments' midpoints in a k-d tree."""

    def __init__(self, start: Array, step: Array) -> None:
        from scipy.spatial import cKDTree

        self.start, self.step = start, step
        n = start.shape[0]
        leaves = -(-n // LEAF)
        self.leaf = np.minimum(np.arange(leaves * LEAF), n - 1).reshape(leaves, LEAF)
        end = start + step
        low, high = np.minimum(start, end)[self.leaf], np.maximum(start, end)[self.leaf]
        self.levels = [(low.min(axis=1), high.max(axis=1))]
        while self.levels[-1][0].shape[0] > 1:
            self.levels.append(_halved(*self.levels[-1]))
        self.midpoints = cKDTree(start + 0.5 * step)

    def nearest(self, points: Array) -> Array:
        """The distance of each of ``points`` (K, 3) to its nearest segment."""
        _, near = self.midpoints.query(points)
        best = segment_distances(points, self.start[near], self.step[near])
        reach = best * (1.0 + SLACK) + SLACK * np.abs(points).max(axis=1)
        rows, nodes = np.arange(points.shape[0]), np.zeros(points.shape[0], dtype=np.int64)
        for low, high in reversed(self.levels[:-1]):  # the root holds every segment
            rows, nodes = np.repeat(rows, 2), np.repeat(2 * nodes, 2)
            nodes[1::2] += 1
            inside = nodes < low.shape[0]
            rows, nodes = rows[inside], nodes[inside]
            gap = np.maximum(np.maximum(low[nodes] - points[rows], points[rows] - high[nodes]), 0)
            keep = np.einsum("ij,ij->i", gap, gap) <= reach[rows] ** 2
            rows, nodes = rows[keep], nodes[keep]
        segments = self.leaf[nodes].ravel()
        rows = np.repeat(rows, LEAF)
        found = segment_distances(points[rows], self.start[segments], self.step[segments])
        np.minimum.at(best, rows, found)
        return best


def _halved(low: Array, high: Array) -> tuple[Array, Array]:
    """The boxes of one tree level up: one around each two (the last alone if odd)."""
    if low.shape[0] % 2:
        low, high = np.vstack([low, low[-1:]]), np.vstack([high, high[-1:]])
    return np.minimum(low[0::2], low[1::2]), np.maximum(high[0::2], high[1::2])
