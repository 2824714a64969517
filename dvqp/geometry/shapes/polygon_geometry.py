"""Vectorised plane geometry of simple polygons: point–edge distances, insideness, crossings."""

from __future__ import annotations

import numpy as np

from dvqp.geometry.shapes.shape import Array


def point_edges(p: Array, v0: Array, v1: Array) -> tuple[Array, Array]:
    """Distance ``(m, E)`` of m points to E edges ``v0 → v1``, and the closest edge points
    ``(m, E, 2)``."""
    e = v1 - v0  # (E, 2)
    w = p[:, None, :] - v0[None, :, :]  # (m, E, 2)
    t = ((w * e).sum(axis=-1) / np.maximum((e * e).sum(axis=-1), 1e-30)).clip(0.0, 1.0)
    closest = v0[None] + t[..., None] * e[None]
    diff = p[:, None, :] - closest
    return np.sqrt((diff * diff).sum(axis=-1)), closest


def inside(p: Array, vertices: Array) -> Array:
    """Even-odd rule: which of m points lie inside the polygon, bool ``(m,)``."""
    v0, v1 = vertices, np.roll(vertices, -1, axis=0)
    y = p[:, 1:2]
    straddles = (v0[None, :, 1] > y) != (v1[None, :, 1] > y)  # (m, E)
    dy = np.where(v1[:, 1] == v0[:, 1], 1.0, v1[:, 1] - v0[:, 1])
    x_cross = v0[None, :, 0] + (y - v0[None, :, 1]) * (v1[None, :, 0] - v0[None, :, 0]) / dy
    return ((straddles & (p[:, 0:1] < x_cross)).sum(axis=1) % 2) == 1


def signed_distance(p: Array, vertices: Array) -> tuple[Array, Array]:
    """Signed distance ``(m,)`` (negative inside) and its gradient ``(m, 2)`` of m points."""
    v0, v1 = vertices, np.roll(vertices, -1, axis=0)
    dist, closest = point_edges(p, v0, v1)
    j = np.argmin(dist, axis=1)
    rows = np.arange(p.shape[0])
    d = dist[rows, j]
    c = closest[rows, j]
    sign = np.where(inside(p, vertices), -1.0, 1.0)
    away = p - c
    norm = np.linalg.norm(away, axis=1)
    # on the outline itself: the outward normal of the edge
    e = (v1 - v0)[j]
    outward = np.column_stack([e[:, 1], -e[:, 0]]) * orientation(vertices)
    outward /= np.maximum(np.linalg.norm(outward, axis=1, keepdims=True), 1e-30)
    scaled = sign[:, None] * away / np.maximum(norm, 1e-30)[:, None]
    grad = np.where((norm > 1e-14)[:, None], scaled, outward)
    return sign * d, grad


def orientation(vertices: Array) -> float:
    """+1 for counter-clockwise vertices, −1 for clockwise (the sign of the area)."""
    return 1.0 if signed_area(vertices) > 0 else -1.0


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
