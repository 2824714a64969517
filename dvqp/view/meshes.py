"""Triangle meshes of the pipe and of the real objects its obstacles stand for, in 3-D.

The pipe's frame is the arm's base frame: z along the pipe axis. A developed-view point
``[l, z, h]`` lies at the angle ``θ = l/R`` round the axis, ``R + h`` from it
(:func:`surface_points`, the inverse of :mod:`dvqp.kinematics.developed_view`'s map). A
:class:`Mesh` is vertices ``(V, 3)`` (m) and triangles ``(F, 3)`` (vertex indices), drawn both
sides, so the triangles' winding does not matter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]

ROUND = 96
"""Vertices round a full circle of the pipe, a ring or a rail."""
ROW = 0.02
"""m: the most the pipe's rows of vertices are apart along its axis."""
TUBE_ROUND = 48
"""Vertices round a branch tube."""


@dataclass(frozen=True)
class Mesh:
    """A named, coloured triangle mesh: ``vertices`` (V, 3), m; ``faces`` (F, 3), int;
    ``color`` (r, g, b) in 0..255."""

    name: str
    vertices: Array
    faces: NDArray[np.int64]
    color: tuple[int, int, int]


def surface_points(l: ArrayLike, z: ArrayLike, h: ArrayLike, radius: float) -> Array:
    """The 3-D points (..., 3), m, of developed-view coordinates ``l``, ``z``, ``h`` (m, of one
    broadcast shape) round a pipe of ``radius`` (m)."""
    l, z, h = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (l, z, h)))
    theta, rho = l / radius, radius + h
    return np.stack([rho * np.cos(theta), rho * np.sin(theta), z], axis=-1)


def _strip(rows: Array, closed: bool) -> tuple[Array, NDArray[np.int64]]:
    """Quads between consecutive rows of points ``(r, p, 3)`` as triangles; each row closed
    round (its last point joined to its first) if ``closed``."""
    r, p = rows.shape[:2]
    idx = np.arange(r * p).reshape(r, p)
    nxt = np.roll(idx, -1, axis=1) if closed else idx[:, 1:]
    a, b = idx[:-1, : nxt.shape[1]], nxt[:-1]
    c, d = idx[1:, : nxt.shape[1]], nxt[1:]
    faces = np.concatenate([np.stack([a, b, d], -1), np.stack([a, d, c], -1)]).reshape(-1, 3)
    return rows.reshape(-1, 3), faces


def pipe_mesh(radius: float, z_low: float, z_high: float, color: tuple[int, int, int]) -> Mesh:
    """The pipe's surface from ``z_low`` to ``z_high`` (m), in rows at most :data:`ROW` apart:
    every vertex at ``radius``."""
    l = np.linspace(0.0, 2.0 * math.pi * radius, ROUND, endpoint=False)
    count = 2 + int((z_high - z_low) / ROW)
    rows = np.stack([surface_points(l, z, 0.0, radius) for z in np.linspace(z_low, z_high, count)])
    vertices, faces = _strip(rows, closed=True)
    return Mesh("pipe", vertices, faces, color)


def ring_mesh(
    name: str,
    z_min: float,
    z_max: float,
    radius: float,
    height: float,
    color: tuple[int, int, int],
) -> Mesh:
    """A band as the ring it stands for: round the pipe from ``z_min`` to ``z_max`` (m),
    ``height`` (m) thick over the surface (its outer face and its two sides)."""
    l = np.linspace(0.0, 2.0 * math.pi * radius, ROUND, endpoint=False)
    profile = [(z_min, 0.0), (z_min, height), (z_max, height), (z_max, 0.0)]
    rows = np.stack([surface_points(l, z, h, radius) for z, h in profile])
    vertices, faces = _strip(rows, closed=True)
    return Mesh(name, vertices, faces, color)


def patch_mesh(
    name: str, outline: Array, radius: float, height: float, color: tuple[int, int, int]
) -> Mesh:
    """A region of the surface raised ``height`` (m): its outline ``(P, 2)`` in (l, z), m
    (closed or not), on the surface and ``height`` above it, the wall between them and the
    top (triangulated in the developed view, so any simple outline)."""
    lz = np.asarray(outline, dtype=np.float64)
    if np.allclose(lz[0], lz[-1]):
        lz = lz[:-1]
    rows = np.stack([surface_points(lz[:, 0], lz[:, 1], h, radius) for h in (0.0, height)])
    vertices, wall = _strip(rows, closed=True)
    cap, top = refine(lz, triangulate(lz), ROW)
    top_vertices = surface_points(cap[:, 0], cap[:, 1], height, radius)
    faces = np.concatenate([wall, top + len(vertices)])
    return Mesh(name, np.concatenate([vertices, top_vertices]), faces, color)


def tube_mesh(
    name: str,
    center: ArrayLike,
    tube_radius: float,
    radius: float,
    length: float,
    color: tuple[int, int, int],
) -> Mesh:
    """A branch inlet as its tube: radius ``tube_radius`` (m) along the pipe's normal at
    ``center`` ``[l0, z0]`` (m), from where it meets the pipe (the inlet's outline, at the
    pipe's ``radius``) to ``length`` (m) above the surface."""
    l0, z0 = (float(v) for v in np.asarray(center, dtype=np.float64))
    theta = l0 / radius
    radial = np.array([math.cos(theta), math.sin(theta), 0.0])
    across = np.array([-math.sin(theta), math.cos(theta), 0.0])
    phi = np.linspace(0.0, 2.0 * math.pi, TUBE_ROUND, endpoint=False)
    u, v = tube_radius * np.cos(phi), tube_radius * np.sin(phi)
    foot = np.sqrt(radius**2 - u**2)  # along the axis, where the tube wall meets the pipe
    rows = []
    for s in np.linspace(0.0, 1.0, 5):
        along = foot + s * (radius + length - foot)
        rows.append(along[:, None] * radial + u[:, None] * across + (z0 + v)[:, None] * [0, 0, 1])
    vertices, faces = _strip(np.stack(rows), closed=True)
    return Mesh(name, vertices, faces, color)


def triangulate(polygon: Array) -> NDArray[np.int64]:
    """Triangles ``(P − 2, 3)`` (indices into ``polygon``) of a simple polygon ``(P, 2)``,
    either way round, by ear clipping."""
    pts = np.asarray(polygon, dtype=np.float64)
    x, y = pts[:, 0], pts[:, 1]
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    left = list(range(len(pts))) if area > 0 else list(range(len(pts)))[::-1]
    triangles = []
    while len(left) > 3:
        for k in range(len(left)):
            a, b, c = left[k - 1], left[k], left[(k + 1) % len(left)]
            if _is_ear(pts, a, b, c, left):
                triangles.append((a, b, c))
                del left[k]
                break
        else:  # only a degenerate (collinear) remainder: fan it
            break
    triangles += [(left[0], left[i], left[i + 1]) for i in range(1, len(left) - 1)]
    return np.array(triangles, dtype=np.int64).reshape(-1, 3)


def refine(
    points: Array, triangles: NDArray[np.int64], longest: float
) -> tuple[Array, NDArray[np.int64]]:
    """Triangles of the plane halved at their longest edge's midpoint until no edge is longer
    than ``longest``: the points (old ones first) and triangles, so that a flat triangle of
    the developed view stays close to the curved surface once mapped onto it."""
    pts = [tuple(p) for p in np.asarray(points, dtype=np.float64)]
    todo, done = [tuple(int(i) for i in t) for t in triangles], []
    while todo:
        tri = todo.pop()
        edges = [(tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]) for i in range(3)]
        a, b, c = max(edges, key=lambda e: math.dist(pts[e[0]], pts[e[1]]))
        if math.dist(pts[a], pts[b]) <= longest:
            done.append(tri)
            continue
        pts.append(tuple((np.asarray(pts[a]) + pts[b]) / 2.0))
        m = len(pts) - 1
        todo += [(a, m, c), (m, b, c)]
    return np.array(pts), np.array(done, dtype=np.int64).reshape(-1, 3)


def _cross(o: Array, a: Array, b: Array) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _is_ear(pts: Array, a: int, b: int, c: int, left: list[int]) -> bool:
    """Whether ``a, b, c`` (counter-clockwise) is a convex corner with no other vertex of
    ``left`` inside it."""
    pa, pb, pc = pts[a], pts[b], pts[c]
    if _cross(pa, pb, pc) <= 0.0:
        return False
    for i in left:
        if i in (a, b, c):
            continue
        p = pts[i]
        if _cross(pa, pb, p) >= 0.0 and _cross(pb, pc, p) >= 0.0 and _cross(pc, pa, p) >= 0.0:
            return False
    return True
