"""Limits of a configuration recomputed independently of dvqp, for the tests.

The frames come from Pinocchio, not dvqp's compiled kinematics; clearances from every shape's
signed distance written in NumPy (to its solid, for an obstacle with a height), each guarded
link taken as the real straight 3-D segment, sampled densely and each sample mapped to the
developed view's ``[l, z, h]`` (not the closest-point computations the planner uses);
heights of the points and of those sampled links (the body links' lowest points, the
holder's) and the tilt from the frames' Cartesian positions; self distances from an exact
closest-point formulation of its own (``tests/oracles/resolution.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from dvqp import Scene
from dvqp.geometry.shapes import Shape
from dvqp.limits import ObstacleDamper, SurfaceHeight, TiltLimit
from tests.oracles.limits import guarded_links
from tests.oracles.resolution import Frames, frames, point_distances
from tests.oracles.resolution import tilt as frame_tilt


def _limit(scene: Scene, kind: type) -> object:
    return next(limit for limit in scene.limits if isinstance(limit, kind))


def _frames(scene: Scene, q: np.ndarray) -> Frames:
    return frames(scene.robot, np.asarray(q, dtype=float), scene.pipe_radius)


def clearances(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Smallest clearance (m) of the whole guarded arm, and of the probe and its holder."""
    if not len(scene.obstacles):
        return math.inf, math.inf
    f = _frames(scene, q)
    k, radius = f.k, scene.pipe_radius
    period = 2.0 * math.pi * radius
    links = real_link_distances(scene.obstacles, f, radius)
    points = point_distances(scene.obstacles, f.guarded[:, :3], period)
    return float(min(links.min(), points.min())), float(links[:, k - 1].min())


def real_link_distances(
    obstacles: Sequence[Shape], f: Frames, radius: float, samples: int = 401
) -> np.ndarray:
    """Signed distance (m) of every real link (the straight 3-D segment, each sample mapped to
    the developed view) to every obstacle, (J, L): ``samples`` samples, then ``samples`` more
    between the neighbours of each obstacle's closest one."""
    coarse = np.linspace(0.0, 1.0, samples)
    period, step = 2.0 * math.pi * radius, coarse[1]
    rail = f.origins.shape[0] > f.k + 1
    ends = guarded_links(f.k, rail)
    out = np.zeros((len(obstacles), len(ends)))
    for i, (a, b) in enumerate(ends):
        pa, pb = f.origins[a], f.origins[b]
        d = point_distances(obstacles, _dv(pa + coarse[:, None] * (pb - pa), radius), period)
        for j, shape in enumerate(obstacles):
            t = coarse[np.argmin(d[j])]
            fine = np.linspace(max(t - step, 0.0), min(t + step, 1.0), samples)[:, None]
            near = point_distances([shape], _dv(pa + fine * (pb - pa), radius), period)
            out[j, i] = min(d[j].min(), near.min())
    return out


def _links(f: Frames, samples: int = 801) -> list[np.ndarray]:
    """Every guarded link as the real 3-D segment, ``samples`` points each (m, (samples, 3))."""
    t = np.linspace(0.0, 1.0, samples)[:, None]
    rail = f.origins.shape[0] > f.k + 1
    return [f.origins[a] + t * (f.origins[b] - f.origins[a]) for a, b in guarded_links(f.k, rail)]


def _dv(p: np.ndarray, radius: float) -> np.ndarray:
    """``[l, z, h]`` of 3-D points (m): ``l = R atan2(y, x)``, ``h = √(x² + y²) − R``."""
    return np.column_stack(
        [radius * np.arctan2(p[:, 1], p[:, 0]), p[:, 2], np.hypot(p[:, 0], p[:, 1]) - radius]
    )


def heights(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Lowest height over the surface (m, from x, y) of the body (its points and the sampled
    body and carriage links) and of the probe with its holder."""
    f = _frames(scene, q)
    k, radius = f.k, scene.pipe_radius
    links = [float(np.hypot(p[:, 0], p[:, 1]).min()) - radius for p in _links(f)]
    rho = np.hypot(f.origins[:, 0], f.origins[:, 1]) - radius
    body = min(rho[:k].min(), *links[: k - 1], *links[k:])
    return float(body), float(min(rho[k], links[k - 1]))


def tilt(scene: Scene, q: np.ndarray) -> float:
    """Angle (rad) of the probe axis from the radial direction, folded into [0, π/2]."""
    angle = frame_tilt(_frames(scene, q))
    return min(angle, math.pi - angle)


def between(qs: np.ndarray, count: int) -> np.ndarray:
    """The samples ``qs`` (N+1, n) and ``count`` configurations evenly between each two."""
    s = np.linspace(0.0, 1.0, count + 2)[:-1, None, None]
    inner = qs[:-1][None] + s * (qs[1:] - qs[:-1])[None]  # (count+1, N, n)
    return np.concatenate([inner.transpose(1, 0, 2).reshape(-1, qs.shape[1]), qs[-1:]])


def worst_breach(scene: Scene, qs: np.ndarray) -> dict[str, float]:
    """For a run's samples ``qs`` (N+1, n): how far each limit was broken at worst (>0 broken).

    A part that starts inside its margin counts from its start value (it may not get worse).
    """
    margin = _limit(scene, ObstacleDamper).margin  # type: ignore[attr-defined]
    h_min = _limit(scene, SurfaceHeight).min_height  # type: ignore[attr-defined]
    min_tilt = _limit(scene, TiltLimit).min_tilt  # type: ignore[attr-defined]
    c0, _ = clearances(scene, qs[0])
    h0, p0 = heights(scene, qs[0])
    t0 = tilt(scene, qs[0])
    out = {
        "clearance": -math.inf,
        "height": -math.inf,
        "probe height": -math.inf,
        "tilt": -math.inf,
        "joint": -math.inf,
    }
    for q in qs:
        if len(scene.obstacles):
            c, _ = clearances(scene, q)
            out["clearance"] = max(out["clearance"], min(margin, c0) - c)
        h, p = heights(scene, q)
        out["height"] = max(out["height"], min(h_min, h0) - h)
        out["probe height"] = max(out["probe height"], min(0.0, p0) - p)
        if min_tilt > 0:
            out["tilt"] = max(out["tilt"], min(min_tilt, t0) - tilt(scene, q))
        joint = np.maximum(q - scene.robot.q_max, scene.robot.q_min - q).max()
        out["joint"] = max(out["joint"], float(joint))
    return out
