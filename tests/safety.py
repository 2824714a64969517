"""Limits of a configuration recomputed independently of dvqp, for the tests.

The frames come from Pinocchio, not dvqp's compiled kinematics; clearances from every shape's
signed distance written in NumPy, each guarded link sampled densely in the developed view (not
the closest-point computations the planner uses); heights and tilt from the frames' Cartesian
positions; self distances from an exact closest-point formulation of its own
(``tests/oracle_resolution.py``).
"""

from __future__ import annotations

import math

import numpy as np

from dvqp import Scene
from dvqp.limits import ObstacleDamper, SurfaceHeight, TiltLimit
from tests.oracle_resolution import Frames, frames, link_distances, point_distances
from tests.oracle_resolution import tilt as frame_tilt


def _limit(scene: Scene, kind: type) -> object:
    return next(limit for limit in scene.limits if isinstance(limit, kind))


def _frames(scene: Scene, q: np.ndarray) -> Frames:
    return frames(scene.robot, np.asarray(q, dtype=float), scene.pipe_radius)


def clearances(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Smallest clearance (m) of the whole guarded arm, and of the probe and its holder."""
    if not len(scene.obstacles):
        return math.inf, math.inf
    f = _frames(scene, q)
    g, k = f.guarded, f.k  # points 1..k, the tool, the rail point
    period = 2.0 * math.pi * scene.pipe_radius
    links = link_distances(scene.obstacles, g, period, k)  # the links' ends included
    points = point_distances(scene.obstacles, g[:, :2], period)
    return float(min(links.min(), points.min())), float(links[:, k - 1].min())


def heights(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Lowest body point height and the probe's height over the surface, m (from x, y)."""
    f = _frames(scene, q)
    rho = np.hypot(f.origins[:, 0], f.origins[:, 1]) - scene.pipe_radius
    return float(rho[: f.k].min()), float(rho[f.k])


def tilt(scene: Scene, q: np.ndarray) -> float:
    """Angle (rad) of the probe axis from the radial direction, folded into [0, π/2]."""
    angle = frame_tilt(_frames(scene, q))
    return min(angle, math.pi - angle)


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
    out = {"clearance": -math.inf, "height": -math.inf, "probe height": -math.inf,
           "tilt": -math.inf, "joint": -math.inf}  # fmt: skip
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
