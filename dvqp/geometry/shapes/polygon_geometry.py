"""Plane geometry of simple polygons checked once, at construction: area, crossing edges."""

from __future__ import annotations

import numpy as np

from dvqp.geometry.shapes.shape import Array


def signed_area(vertices: Array) -> float:
    """Shoelace area, m² (positive counter-clockwise)."""
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def crossings(a: Array, b: Array, v0: Array, v1: Array) -> Array:
    """Which of m segments ``a → b`` cross or touch any of E edges ``v0 → v1``: bool ``(m,)``."""

    def orient(p: Array, q: Array, r: Array) -> Array:
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (
            r[..., 0] - p[..., 0]
        )

    A, B = a[:, None, :], b[:, None, :]
    C, D = v0[None], v1[None]
    o1, o2 = orient(A, B, C), orient(A, B, D)
    o3, o4 = orient(C, D, A), orient(C, D, B)
    return ((o1 * o2 <= 0) & (o3 * o4 <= 0)).any(axis=1)


def self_intersects(vertices: Array) -> bool:
    """True if two non-adjacent edges of the closed polygon cross or touch."""
    v0, v1 = vertices, np.roll(vertices, -1, axis=0)
    n = vertices.shape[0]
    for i in range(n):
        others = [j for j in range(n) if j not in (i, (i + 1) % n, (i - 1) % n)]
        if others and crossings(v0[i : i + 1], v1[i : i + 1], v0[others], v1[others])[0]:
            return True
    return False
