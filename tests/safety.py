"""Limits of a configuration recomputed independently of dvqp's limit code, for the tests.

Clearances come from sampling every guarded segment densely in the developed view and taking
the shapes' point distances there (not the closest-point computations of segments, which the
planner uses); heights and tilt from the frames' Cartesian positions.
"""

from __future__ import annotations

import math

import numpy as np

from dvqp import KinematicState, Scene
from dvqp.limits import ObstacleDamper, SurfaceHeight, TiltLimit

SAMPLES_PER_LINK = 400


def _limit(scene: Scene, kind: type) -> object:
    return next(limit for limit in scene.limits if isinstance(limit, kind))


def clearances(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Smallest clearance (m) of the whole guarded arm, and of the probe and its holder."""
    state = KinematicState.compute(scene.robot, q, scene.pipe_radius)
    period = 2.0 * math.pi * scene.pipe_radius
    lz = np.array([[p[0], p[1]] for p in state.guarded])  # points 1..k, then the tool
    t = np.linspace(0.0, 1.0, SAMPLES_PER_LINK)
    best, probe = math.inf, math.inf
    for i in range(lz.shape[0] - 1):
        a, b = lz[i], lz[i + 1].copy()
        b[0] = a[0] + ((b[0] - a[0] + period / 2) % period - period / 2)
        pts = a + t[:, None] * (b - a)
        for o in scene.obstacles:
            c = float(o.point_distance(pts, period)[0].min())
            best = min(best, c)
            if i == lz.shape[0] - 2:
                probe = min(probe, c)
    return best, probe


def heights(scene: Scene, q: np.ndarray) -> tuple[float, float]:
    """Lowest body point height and the probe's height over the surface, m (from x, y)."""
    state = KinematicState.compute(scene.robot, q, scene.pipe_radius)
    rho = np.hypot(state.origins[:, 0], state.origins[:, 1]) - scene.pipe_radius
    return float(rho[:-1].min()), float(rho[-1])


def tilt(scene: Scene, q: np.ndarray) -> float:
    """Angle (rad) of the probe axis from the radial direction, folded into [0, π/2]."""
    state = KinematicState.compute(scene.robot, q, scene.pipe_radius)
    o, a = state.origins[-1], state.axes[-1]
    radial = np.array([o[0], o[1], 0.0]) / math.hypot(o[0], o[1])
    angle = math.acos(max(-1.0, min(1.0, float(a @ radial))))
    return min(angle, math.pi - angle)


def worst_breach(scene: Scene, qs: np.ndarray) -> dict[str, float]:
    """For a run's samples ``qs`` (N+1, n): how far each limit was broken at worst (>0 broken).

    A part that starts inside its margin counts from its start value (it may not get worse).
    """
    margin = _limit(scene, ObstacleDamper).margin  # type: ignore[attr-defined]
    h_min = _limit(scene, SurfaceHeight).min_height  # type: ignore[attr-defined]
    min_tilt = _limit(scene, TiltLimit).min_tilt  # type: ignore[attr-defined]
    c0, _ = clearances(scene, qs[0]) if len(scene.obstacles) else (math.inf, math.inf)
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
