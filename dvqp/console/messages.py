"""The ``scene`` message a client gets once at connect: all it needs to draw around the arm
(the developed view, the cross-section) without reading the scene file."""

from __future__ import annotations

from typing import Any

import numpy as np

from dvqp.console import protocol
from dvqp.scenes.scene import Scene


def limit_value(scene: Scene, attribute: str) -> float | None:
    """The first of the scene's limits that has ``attribute`` (``min_height``, ``margin``)."""
    for limit in scene.limits:
        value = getattr(limit, attribute, None)
        if isinstance(value, (int, float)):
            return protocol.finite(float(value))
    return None


def obstacle_info(shape: Any) -> dict[str, Any]:
    """``{"kind", "outline"}`` of one shape; a band also has ``"z": [z_min, z_max]``."""
    outline = np.asarray(shape.outline(), dtype=np.float64)
    info: dict[str, Any] = {"kind": str(shape.kind), "outline": protocol.rounded(outline)}
    if np.isnan(outline[:, 0]).all():
        info["z"] = protocol.rounded(outline[:, 1])
    return info


def scene_message(scene: Scene, backend: str) -> dict[str, Any]:
    """The ``scene`` message of ``scene`` driven with ``backend``."""
    return {
        "type": "scene",
        "name": scene.name,
        "description": scene.description,
        "backend": backend,
        "dt": scene.dt,
        "pipe_radius": scene.pipe_radius,
        "weld": scene.weld,
        "orbital_level": scene.orbital_level,
        "min_height": limit_value(scene, "min_height"),
        "margin": limit_value(scene, "margin"),
        "points": scene.robot.n_points,
        "speed_limits": {
            "linear": protocol.MAX_LINEAR_SPEED,
            "angular": protocol.MAX_ANGULAR_SPEED,
        },
        "obstacles": [obstacle_info(shape) for shape in scene.obstacles],
    }
