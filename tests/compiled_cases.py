"""Obstacle sets and configurations shared by the compiled-kernel tests.

Each case is a robot, a pipe radius, an obstacle set and configurations near a start
configuration. The mixed sets are built around the guarded points of their start state, the
shape classes interleaved (circle, band, circle, polygon, inlet, ...), so that small offsets
put points and links inside every class and the rows of a class are not contiguous.
:class:`Dot` is a circle of one's own (a subclass of dvqp's, measured by its NumPy methods).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

import dvqp
from dvqp import KinematicState, ObstacleSet, Robot
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon
from tests.common import LINK_LENGTHS, PIPE_RADIUS, Q0
from tests.oracles.geometry import circle_points, circle_segments

SCENES = Path(__file__).resolve().parent.parent / "scenes"
BUNDLED_WITH_OBSTACLES = ("paper-two-inlets", "paper-inlets", "pipe-rack", "many-obstacles")
SEAM_SHIFT = 2.6
"""rad added to joint 1 (the carriage round the pipe) so that body point 4 sits at l ≈ πR."""


@dataclass(frozen=True)
class Case:
    """A robot in a pipe of ``radius`` (m) among ``obstacles``, near ``q0`` (rad)."""

    robot: Robot
    radius: float
    obstacles: ObstacleSet
    q0: NDArray[np.float64]

    def configurations(self, count: int, spread: float, seed: int = 0) -> NDArray[np.float64]:
        """``q0`` and ``count − 1`` uniform offsets of at most ``spread`` rad, (count, n)."""
        rng = np.random.default_rng(seed)
        offsets = rng.uniform(-spread, spread, size=(count, self.q0.shape[0]))
        offsets[0] = 0.0
        return self.q0 + offsets

    def state(self, q: NDArray[np.float64]) -> KinematicState:
        """The kinematics at ``q``."""
        return KinematicState.compute(self.robot, q, self.radius)


class Dot(Circle):
    """A circle of one's own: a subclass of dvqp's :class:`Circle` is not dvqp's own class, so
    dvqp measures it by its NumPy methods (the oracle's closed form). ``calls`` counts them."""

    calls: ClassVar[list[str]] = []

    def point_distance(self, lz, period):  # type: ignore[no-untyped-def]
        Dot.calls.append("point_distance")
        return circle_points(self.center, self.radius, lz, period)

    def segment_distance(self, a, b, period):  # type: ignore[no-untyped-def]
        Dot.calls.append("segment_distance")
        return circle_segments(self.center, self.radius, a, b, period)


def scene_case(name: str) -> Case:
    """A bundled scene's robot, pipe, obstacles and start configuration."""
    scene = dvqp.load_scene(SCENES / f"{name}.toml")
    return Case(scene.robot, scene.pipe_radius, scene.obstacles, np.array(scene.q0))


def mixed_case(robot: Robot, seam: bool = False, heights: bool = False) -> Case:
    """Shapes of every class, interleaved, around the guarded points at the start (with
    ``seam``: the arm turned round the pipe so that it straddles ``l = ±πR``; with
    ``heights``: each but two with a height, a few cm above or below the parts near it, so
    that parts are over, beside and past the edge of a solid)."""
    q0 = np.array(Q0)
    if seam:
        q0[0] += SEAM_SHIFT
    g = KinematicState.compute(robot, q0, PIPE_RADIUS).guarded[:, :2]
    period = 2.0 * math.pi * PIPE_RADIUS
    link3 = g[3] + 0.5 * np.array([_wrap(g[4, 0] - g[3, 0], period), g[4, 1] - g[3, 1]])
    link1 = g[1] + 0.5 * np.array([_wrap(g[2, 0] - g[1, 0], period), g[2, 1] - g[1, 1]])
    box = np.array([[-0.03, -0.02], [0.035, -0.025], [0.03, 0.03], [-0.025, 0.02]])
    shapes = [
        Circle(g[1] + [0.01, -0.02], 0.05, 20.0),
        Band(g[2, 1] - 0.03, g[2, 1] + 0.02, 10.0),
        Circle(link3 + np.array([0.0, 0.01]), 0.04, 15.0),
        Polygon(g[4] + box, 5.0),
        Inlet(g[0] + [0.02, 0.01], 0.06, PIPE_RADIUS, 8.0),
        Circle(g[0] + [-0.4, 0.3], 0.03, 3.0),  # never reached
        Polygon(link1 + 1.5 * box[::-1], 12.0),  # clockwise
        Band(g[5, 1] + 0.005, g[5, 1] + 0.04, 2.0),
        Inlet(g[3] + [0.01, -0.015], 0.05, PIPE_RADIUS, 6.0),
    ]
    if heights:  # m above the surface; the body points ride at 0.07 to 0.09 m
        tops = (0.05, 0.03, 0.095, 0.06, math.inf, 0.02, 0.07, math.inf, 0.065)
        shapes = [replace(shape, height=top) for shape, top in zip(shapes, tops, strict=True)]
    return Case(robot, PIPE_RADIUS, ObstacleSet(shapes), q0)


def paper_robot() -> Robot:
    """The paper's 13-DOF arm."""
    return Robot.ndt13(LINK_LENGTHS)


def spoil(*arrays: NDArray[np.float64]) -> None:
    """Fill ``arrays`` with NaN, so that an entry a kernel forgets shows."""
    for a in arrays:
        a.fill(np.nan)


def _wrap(dl: float, period: float) -> float:
    return (dl + 0.5 * period) % period - 0.5 * period
