"""The 3-D geometry of a scene and a run, built once for the browser view and the still.

:func:`scene_3d` turns a scene and a sequence of configurations into arrays: the pipe, each
obstacle as the real object it stands for (a branch inlet as its tube, a band as a ring, a
circle or a polygon pad as a raised patch of the surface), the rail, the weld, the probe's
path, and per sample the arm's chain (rail point or base, body points, probe: the guarded
frames' origins, from the compiled kinematics) with the links at their obstacle margin
marked. An obstacle with a height is drawn as tall as it is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.proximity import proximity
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.state import KinematicState
from dvqp.limits.obstacle_damper import ObstacleDamper
from dvqp.scenes import Scene
from dvqp.view.meshes import ROUND, Mesh, patch_mesh, pipe_mesh, ring_mesh, surface_points
from dvqp.view.meshes import tube_mesh as _tube

Array = NDArray[np.float64]
Color = tuple[int, int, int]

COLORS: dict[str, Color] = {
    "pipe": (70, 120, 200),
    "obstacle": (40, 160, 70),
    "arm": (245, 140, 20),
    "margin": (215, 25, 25),
    "rail": (80, 80, 80),
    "weld": (255, 255, 255),
    "path": (160, 40, 200),
}
"""The view's colours (r, g, b): the pipe blue, the obstacles green, the arm orange and a link
at its margin red, the rail grey, the weld white, the probe's path purple."""
PATCH_HEIGHT = 0.01
"""m: how far a raised patch (a circle or a polygon pad) without a height is drawn over the
surface (the obstacle itself is unbounded: a wall to the sky)."""
RING_HEIGHT = 0.03
"""m: how far a band's ring without a height is drawn over the surface."""
TUBE_LENGTH = 0.25
"""m: how far a branch inlet's tube without a height is drawn over the surface."""
MARGIN_SLACK = 1e-3
"""m: a link whose clearance is within this of the obstacle margin (or below it) is drawn
at its margin."""


@dataclass(frozen=True)
class Polyline:
    """A named, coloured polyline: ``points`` (P, 3), m."""

    name: str
    points: Array
    color: Color


@dataclass(frozen=True)
class Scene3D:
    """A scene and a run in 3-D (m, the pipe's frame: z along its axis).

    Attributes
    ----------
    title : str
        What it shows.
    pipe_radius : float
        ``R``, m.
    meshes, lines : tuple
        The pipe and the obstacles (:class:`~dvqp.view.meshes.Mesh`); the rail, the weld and
        the probe's path (:class:`Polyline`).
    t : ndarray, shape (N,)
        Time of each sample, s.
    chain : ndarray, shape (N, c, 3)
        The arm at each sample: the rail point (if the arm has one), the body points and the
        probe, in order along the arm; link i joins points i and i + 1.
    at_margin : ndarray of bool, shape (N, c − 1)
        Link i's clearance is within :data:`MARGIN_SLACK` of the obstacle margin or below.
    margin : float or None
        The obstacle margin, m (None: the scene keeps none).
    """

    title: str
    pipe_radius: float
    meshes: tuple[Mesh, ...]
    lines: tuple[Polyline, ...]
    t: Array
    chain: Array
    at_margin: NDArray[np.bool_]
    margin: float | None


def scene_3d(scene: Scene, q: Array, t: Array, title: str) -> Scene3D:
    """The 3-D geometry of ``scene`` with the arm at the configurations ``q`` (N, n), rad, at
    times ``t`` (N,), s.

    Raises
    ------
    SingularConfigurationError
        A configuration puts a guarded frame on the pipe axis.
    """
    radius, obstacles = scene.pipe_radius, scene.obstacles
    margin = next((lim.margin for lim in scene.limits if isinstance(lim, ObstacleDamper)), None)
    states = [KinematicState.compute(scene.robot, qk, radius) for qk in np.asarray(q)]
    k, rail = scene.robot.n_points, scene.robot.has_rail
    order = ([k + 1] if rail else []) + list(range(k + 1))  # rail, body points, probe
    chain = np.array([np.asarray(s.origins)[order] for s in states]).reshape(len(states), -1, 3)
    # link_ends order: body links, holder, carriage; the chain's: carriage, body links, holder
    links = ([k] if rail else []) + list(range(k))
    at_margin = np.zeros((len(states), len(links)), dtype=bool)
    if margin is not None and len(obstacles):
        for n, state in enumerate(states):
            clearance = proximity(state, obstacles).link_clearance.min(axis=0)
            at_margin[n] = clearance[links] <= margin + MARGIN_SLACK
    z_all = np.concatenate([chain[..., 2].ravel(), *[list(s.z_range) for s in obstacles]])
    z_low, z_high = float(np.min(z_all)) - 0.15, float(np.max(z_all)) + 0.15
    shapes = [obstacle_mesh(f"obstacle{j + 1}", s, radius) for j, s in enumerate(obstacles)]
    meshes = (pipe_mesh(radius, z_low, z_high, COLORS["pipe"]), *shapes)
    lines = _lines(scene, chain)
    return Scene3D(
        title, radius, meshes, lines, np.asarray(t, dtype=np.float64), chain, at_margin, margin
    )


def obstacle_mesh(name: str, shape: Shape, radius: float) -> Mesh:
    """The real object an obstacle shape stands for, as tall as its height: an inlet's tube
    (a stub), a band's ring, or (a circle, a polygon pad, a shape of your own) its outline
    raised as a patch; one without a height is drawn as tall as :data:`TUBE_LENGTH`,
    :data:`RING_HEIGHT` or :data:`PATCH_HEIGHT`."""
    color, kind = COLORS["obstacle"], shape.kind

    def tall(default: float) -> float:
        return float(shape.height) if shape.bounded else default

    if kind == "inlet":
        return _tube(name, shape.center, shape.radius, radius, tall(TUBE_LENGTH), color)  # type: ignore[attr-defined]
    if kind == "band":
        return ring_mesh(name, shape.z_min, shape.z_max, radius, tall(RING_HEIGHT), color)  # type: ignore[attr-defined]
    return patch_mesh(name, shape.outline(), radius, tall(PATCH_HEIGHT), color)


def _lines(scene: Scene, chain: Array) -> tuple[Polyline, ...]:
    """The rail (a circle through the rail point), the circumferential weld, the path."""
    radius, lines = scene.pipe_radius, []
    l_round = np.linspace(0.0, 2.0 * np.pi * radius, ROUND + 1)
    if scene.robot.rail_frame is not None:  # (a standing arm's base is no rail)
        x, y, z = chain[0, 0]
        lines.append(
            Polyline(
                "rail", surface_points(l_round, z, np.hypot(x, y) - radius, radius), COLORS["rail"]
            )
        )
    if scene.weld is not None:
        lines.append(
            Polyline("weld", surface_points(l_round, scene.weld, 1e-3, radius), COLORS["weld"])
        )
    if len(chain) > 1:  # the probe's path over the run
        lines.append(Polyline("path", chain[:, -1].copy(), COLORS["path"]))
    elif scene.path is not None:  # the start pose: the path the probe is to follow
        w = scene.path.waypoints
        lines.append(
            Polyline("path", surface_points(w[:, 0], w[:, 1], w[:, 2], radius), COLORS["path"])
        )
    return tuple(lines)
