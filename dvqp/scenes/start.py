"""Checks of a scene's start configuration.

A start that puts a body point or the tool inside the pipe (h < 0), or the tool inside an
obstacle, is refused. A body point below ``[constraints] min_height`` or within an obstacle's
margin is allowed: the QP's dampers then forbid it to get worse and the objective pushes it
out (``docs/scenes.md``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import distances
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.scenes.fields import Fields, join


def check_start(
    f: Fields, robot: Robot, q0: NDArray[np.float64], radius: float, obstacles: ObstacleSet
) -> None:
    """Every point of the arm must start outside the pipe, the tool also outside the obstacles.

    The configuration must be regular (no point on the pipe axis).
    """
    try:
        state = KinematicState.compute(robot, q0, radius)
    except DvqpError as exc:
        f.fail("robot.q0", str(exc))
    tool = state.tool
    heights = [*state.points[:, 2], tool[2]]
    for i, (frame, h) in enumerate(zip(robot.frame_names[: len(heights)], heights, strict=True)):
        if h < 0.0:
            part = "the tool" if i == robot.n_points else f"body point {i + 1}"
            f.fail("robot.q0", f"{part} (frame {frame!r}) starts inside the pipe: h = {h:.4g} m")
    inside, _ = distances(obstacles, tool[None, :2], 2.0 * np.pi * radius)
    for i, o in enumerate(obstacles):
        d = float(inside[i, 0])
        if d < 0.0:
            f.fail(
                join("obstacles", i),
                f"covers the tool's start point [l, z] = [{tool[0]:.4g}, {tool[1]:.4g}] m "
                f"({-d * 1e3:.3g} mm inside the {o.kind})",
            )
