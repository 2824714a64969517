"""Checks of a scene's start configuration.

A start that puts a body point or the tool inside the pipe (h < 0), or the tool inside an
obstacle, is refused. A body point below ``[constraints] min_height`` or within an obstacle's
margin is allowed: the QP's dampers then forbid it to get worse and the objective pushes it
out (``docs/scenes.md``). But a ``min_height`` above the rail point, where the rail holds it at
a fixed height, can never be met: the carriage link rises from that point, so its lowest point
is at most that high. Such a scene is refused with both numbers.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import distances
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.height import SurfaceHeight
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


def check_floor(
    f: Fields, robot: Robot, q0: NDArray[np.float64], radius: float, limits: tuple[object, ...]
) -> None:
    """Refuse a ``min_height`` above the height of a rail point that no joint can raise.

    The rail point's height is fixed when it is the same (to 1e-9 m) at the start and at eight
    configurations drawn within the joint limits (it depends analytically on the joints, so a
    height that moves would not repeat by chance); a rail that moves is left to the run.
    """
    floors = [x.min_height for x in limits if isinstance(x, SurfaceHeight)]
    if not floors or not robot.has_rail:
        return
    low = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    high = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    draws = np.random.default_rng(0).uniform(low, high, size=(8, robot.n))
    heights = []
    for q in (q0, *draws):
        try:
            heights.append(float(KinematicState.compute(robot, q, radius).guarded[-1, 2]))
        except DvqpError:  # a singular draw proves nothing either way
            continue
    rail = heights[0]
    if max(floors) > rail and np.ptp(heights) <= 1e-9:
        f.fail(
            "constraints.min_height",
            f"{max(floors):.4g} m is above the rail point (frame {robot.rail_frame!r}), which "
            f"the rail holds at h = {rail:.4g} m: the carriage link rising from it can never "
            "be that high",
        )
