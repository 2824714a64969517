"""Checks of a scene's start configuration."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.geometry.obstacle import ObstacleSet, offsets
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.scenes.fields import Fields, join


def check_start(
    f: Fields, robot: Robot, q0: NDArray[np.float64], radius: float, obstacles: ObstacleSet
) -> None:
    """The tool's start point must be regular and outside every obstacle."""
    try:
        tool = KinematicState.compute(robot, q0, radius).tool
    except DvqpError as exc:
        f.fail("robot.q0", str(exc))
    for i, o in enumerate(obstacles):
        d = float(np.linalg.norm(offsets(tool[None, :2], o.center[None], radius)))
        if d < o.radius:
            f.fail(
                join("obstacles", i),
                f"covers the tool's start point [l, z] = [{tool[0]:.4g}, {tool[1]:.4g}] m "
                f"(distance {d:.4g} m < radius {o.radius:g} m)",
            )
