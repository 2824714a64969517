"""Obstacles placed around the start configuration, shared by the limit tests."""

from __future__ import annotations

import numpy as np

from dvqp import KinematicState, Obstacle, ObstacleSet

DT = 0.005


def near_obstacles(state: KinematicState) -> ObstacleSet:
    """One circle 2 cm from point 3, one crossing near link 4's middle, one far away."""
    p = state.points[:, :2]
    mid = 0.5 * (p[3] + p[4])
    return ObstacleSet(
        [
            Obstacle(p[2] + np.array([0.0, 0.05]), 0.03),
            Obstacle(mid + np.array([0.0, 0.045]), 0.03),
            Obstacle(np.array([-0.5, -1.0]), 0.05),
        ]
    )
