"""Checks of a scene's start configuration.

A start that puts any guarded part of the arm inside the pipe (h < 0) is refused: a body
point, the tool, the lead point (the rail point, or the base of an arm standing on the pipe),
or the lowest point of a link's chord (a body link, the probe holder, the lead link). So is a
start with the tool, or a standing arm's base (which never moves), inside an obstacle's solid
(below its height, if it has one). A body point below ``[constraints] min_height`` or within
an obstacle's margin is allowed: the QP's dampers then forbid it to get worse and the
objective pushes it out (``docs/scenes.md``). But a ``min_height`` above the rail point, where
the rail holds it at a fixed height, can never be met: the carriage link rises from that
point, so its lowest point is at most that high. Such a scene is refused with both numbers.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import distances
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.height import SurfaceHeight, lowest_chords
from dvqp.scenes.fields import Fields, join
from dvqp.workspace import link_ends


def check_start(
    f: Fields, robot: Robot, q0: NDArray[np.float64], radius: float, obstacles: ObstacleSet
) -> None:
    """Every part of the arm must start outside the pipe; the tool and a standing arm's base
    also outside the obstacles.

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
    _lead_outside(f, robot, state)
    _links_outside(f, state)
    period = 2.0 * np.pi * radius
    inside, _ = distances(obstacles, tool[None, :3], period)  # the solids
    for i, o in enumerate(obstacles):
        d = float(inside[i, 0])
        if d < 0.0:
            where = (
                f"[l, z, h] = [{tool[0]:.4g}, {tool[1]:.4g}, {tool[2]:.4g}]"
                if o.bounded
                else f"[l, z] = [{tool[0]:.4g}, {tool[1]:.4g}]"
            )
            f.fail(
                join("obstacles", i),
                f"covers the tool's start point {where} m ({-d * 1e3:.3g} mm inside the {o.kind})",
            )
    if robot.base_frame is not None:
        base = state.guarded[robot.n_points + 1]
        inside, _ = distances(obstacles, base[None, :], period)
        for i, o in enumerate(obstacles):
            d = float(inside[i, 0])
            if d < 0.0:
                f.fail(
                    join("obstacles", i),
                    f"covers the arm's base (frame {robot.base_frame!r}) at [l, z, h] = "
                    f"[{base[0]:.4g}, {base[1]:.4g}, {base[2]:.4g}] m ({-d * 1e3:.3g} mm inside "
                    f"the {o.kind}), which never moves",
                )


def _lead_outside(f: Fields, robot: Robot, state: KinematicState) -> None:
    """Refuse a lead point (the rail point, a standing arm's base) inside the pipe."""
    if robot.lead_frame is None:
        return
    h = float(state.guarded[robot.n_points + 1, 2])
    if h < 0.0:
        base = robot.base_frame is not None
        part = "the arm's base" if base else "the rail point"
        f.fail(
            "robot.base" if base else "robot.q0",
            f"{part} (frame {robot.lead_frame!r}) starts inside the pipe: h = {h:.4g} m "
            f"({-h * 1e3:.3g} mm inside the pipe wall)",
        )


def _links_outside(f: Fields, state: KinematicState) -> None:
    """Refuse a start whose link chords (body links, the lead link, the probe holder) dip
    into the pipe, naming the lowest."""
    k, names = state.k, state.part_names
    low, which, holder = lowest_chords(
        np.array(state.guarded),
        np.array(state.origins),
        link_ends(k, state.rail),
        k,
        state.radius,
        -1,  # every link, a standing arm's base link too
    )
    for h, link in ((low, int(which)), (holder, k - 1)):
        if h < 0.0 and link >= 0:
            f.fail(
                "robot.base" if names.base and link == k else "robot.q0",
                f"link {names.link(link)!r} starts inside the pipe: its lowest point at "
                f"h = {h:.4g} m ({-h * 1e3:.3g} mm inside the pipe wall)",
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
    if not floors or robot.rail_frame is None:
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
