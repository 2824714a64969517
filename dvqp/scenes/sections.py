"""Readers of the sections of a scene file for :mod:`dvqp.scenes.scene` (private).

Each reader takes the parsed TOML document (or a section of it) and returns typed objects,
raising :class:`~dvqp.errors.SceneError` through :class:`~dvqp.scenes.fields.Fields`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.scenes.fields import Fields, join
from dvqp.errors import DvqpError, ParameterError
from dvqp.limits import DamperParameters
from dvqp.objective import Objective
from dvqp.geometry.obstacle import Obstacle, offsets
from dvqp.kinematics.robot import Robot
from dvqp.motion.simulate import MAX_STEPS, JogSegment
from dvqp.kinematics.state import KinematicState

ROBOT_KEYS = ("model", "link_lengths", "urdf", "points", "tool", "q0", "q_min", "q_max", "qd_max",
              "weights")  # fmt: skip
OBJECTIVE_KEYS = ("orbital_level", "k_height", "k_obstacle", "gain")
CONSTRAINT_KEYS = ("min_height", "margin", "influence", "damper_gain")
PATH_KEYS = ("waypoints", "speed", "gain", "tolerance", "heading_tolerance")
MODELS = ("ndt13",)


HEADING_ARM = 0.1
"""m/rad: a path segment's heading change counts as this much length (at 0.02 m/s along the
path, the probe turns at 0.2 rad/s)."""


@dataclass(frozen=True)
class PathMotion:
    """A DV path for the tool, followed with position feedback.

    Attributes
    ----------
    waypoints : ndarray, shape (m, 4)
        ``[l, z, h, α]`` (m, m, m, rad), l unwrapped (it may run past ``±πR``).
    speed : float
        Speed along the (l, z, h) polyline, m/s.
    gain : float
        Feedback gain ``K``, 1/s.
    tolerance : float
        Largest final position error (l, z, h) counted as reached, m.
    heading_tolerance : float
        Largest final heading error counted as reached, rad.
    """

    waypoints: NDArray[np.float64]
    speed: float
    gain: float = 5.0
    tolerance: float = 0.005
    heading_tolerance: float = 0.05

    @staticmethod
    def segment_lengths(nodes: NDArray[np.float64]) -> NDArray[np.float64]:
        """Length (m) of each segment between consecutive ``[l, z, h, α]`` nodes, shape (m−1,).

        A segment lasts as long as its (l, z, h) length or its heading change counted at
        :data:`HEADING_ARM` m/rad, whichever is longer, so a turn in place takes time too.
        """
        delta = np.diff(nodes, axis=0)
        return np.maximum(np.linalg.norm(delta[:, :3], axis=1), HEADING_ARM * np.abs(delta[:, 3]))


def pipe(f: Fields, doc: dict[str, Any]) -> tuple[float, float | None]:
    """``[pipe]``: the radius (m, > 0) and the optional weld z (m)."""
    pipe = f.table(doc, "pipe", "", ("radius", "weld"))
    with f.mapped("pipe"):
        radius = _validate.positive("radius", f.number(pipe, "radius", "pipe"))
    return radius, f.number(pipe, "weld", "pipe", None) if "weld" in pipe else None


def robot(
    f: Fields, doc: dict[str, Any], base_dir: Path
) -> tuple[Robot, NDArray[np.float64], NDArray[np.float64]]:
    """The arm, its start configuration (rad) and the diagonal of W, each checked."""
    t = f.table(doc, "robot", "", ROBOT_KEYS)
    arm = _arm(f, t, base_dir)
    q0 = f.vector(t, "q0", "robot", arm.n)
    _check_limits(f, arm, q0)
    weights = f.vector(t, "weights", "robot", arm.n, scalar=True, default=1.0)
    if np.any(weights <= 0):
        f.fail("robot.weights", "must be > 0")
    return arm, _validate.readonly(q0), _validate.readonly(weights)


def _arm(f: Fields, t: dict[str, Any], base_dir: Path) -> Robot:
    if ("model" in t) == ("urdf" in t):
        f.fail("robot", "give exactly one of 'model' (built in) or 'urdf' (a file)")
    if "model" in t:
        model = f.string(t, "model", "robot")
        if model not in MODELS:
            f.fail("robot.model", f"unknown model {model!r} (known: {', '.join(MODELS)})")
        for key in ("points", "tool"):
            if key in t:
                f.fail(join("robot", key), "only with 'urdf'")
        lengths = f.vector(t, "link_lengths", "robot", 7)
        limits = _limits(f, t, 13)
        with f.mapped("robot"):
            return Robot.ndt13(lengths, **{k: v for k, v in limits.items() if v is not None})
    if "link_lengths" in t:
        f.fail("robot.link_lengths", "only with model = 'ndt13'")
    urdf = base_dir / f.string(t, "urdf", "robot")
    points, tool = f.strings(t, "points", "robot"), f.string(t, "tool", "robot")
    if not urdf.is_file():
        f.fail("robot.urdf", f"no such file: {urdf}")
    try:
        loaded = Robot.from_urdf(urdf, points, tool)
    except ParameterError as exc:
        _frame_error(f, exc, tool)
    except DvqpError as exc:
        f.fail("robot.urdf", str(exc))
    limits = _limits(f, t, loaded.n)
    if limits["qd_max"] is None:
        limits["qd_max"] = loaded.qd_max
    with f.mapped("robot"):
        return Robot(loaded.model, points, tool, name=loaded.name, **limits)


def _limits(f: Fields, t: dict[str, Any], n: int) -> dict[str, NDArray[np.float64] | None]:
    """q_min, q_max (±inf allowed: no limit) and qd_max as given, or None."""
    return {
        key: f.vector(t, key, "robot", n, scalar=True, infinite=key != "qd_max")
        if key in t
        else None
        for key in ("q_min", "q_max", "qd_max")
    }


def _frame_error(f: Fields, exc: ParameterError, tool: str) -> None:
    if exc.name != "frames":
        f.fail(join("robot", exc.name), exc.reason)
    key = "tool" if exc.reason.startswith(f"no frame named {tool!r}") else "points"
    f.fail(join("robot", key), exc.reason)


def _check_limits(f: Fields, robot: Robot, q0: NDArray[np.float64]) -> None:
    for i, (q, lo, hi) in enumerate(zip(q0, robot.q_min, robot.q_max, strict=True)):
        if not lo - 1e-12 <= q <= hi + 1e-12:
            f.fail(f"robot.q0[{i}]", f"{q:g} rad is outside [q_min, q_max] = [{lo:g}, {hi:g}] rad")


def obstacles(f: Fields, doc: dict[str, Any]) -> tuple[Obstacle, ...]:
    """``[[obstacles]]``: circles in the (l, z) plane (none if absent)."""
    out = []
    for i, t in enumerate(f.tables(doc, "obstacles", "", ("center", "radius", "weight"))):
        prefix = join("obstacles", i)
        center = f.vector(t, "center", prefix, 2)
        radius, weight = f.number(t, "radius", prefix), f.number(t, "weight", prefix, 1.0)
        with f.mapped(prefix):
            out.append(Obstacle(center, radius, weight))
    return tuple(out)


def objective(f: Fields, doc: dict[str, Any], k: int, obstacles: tuple[Obstacle, ...]) -> Objective:
    """``[objective]`` for ``k`` body points, with the obstacles."""
    t = f.table(doc, "objective", "", OBJECTIVE_KEYS)
    level = f.number(t, "orbital_level", "objective")
    kh = f.vector(t, "k_height", "objective", k, scalar=True, default=1.0)
    ko = f.vector(t, "k_obstacle", "objective", k, scalar=True, default=1.0)
    gain = f.number(t, "gain", "objective", 1.0)
    with f.mapped("objective"):
        return Objective(k, level, kh, ko, obstacles, gain)


def dampers(f: Fields, doc: dict[str, Any]) -> DamperParameters:
    """``[constraints]`` (optional): the QP's damper and height parameters."""
    t = f.table(doc, "constraints", "", CONSTRAINT_KEYS, required=False)
    default = DamperParameters()
    values = {
        "min_height": f.number(t, "min_height", "constraints", default.min_height),
        "margin": f.number(t, "margin", "constraints", default.margin),
        "influence": f.number(t, "influence", "constraints", default.influence),
        "gain": f.number(t, "damper_gain", "constraints", default.gain),
    }
    with f.mapped("constraints"):
        return DamperParameters(**values)


def motion(
    f: Fields, doc: dict[str, Any]
) -> tuple[float, tuple[JogSegment, ...], PathMotion | None]:
    """``dt`` (s), and the JOG segments or the path."""
    motion = f.table(doc, "motion", "", ("dt", "jog", "path"))
    with f.mapped("motion"):
        dt = _validate.positive("dt", f.number(motion, "dt", "motion"))
    jog, path = _motion(f, motion)
    if path is None:
        steps = sum(max(1, round(seg.duration / dt)) for seg in jog)
    else:
        steps = float(PathMotion.segment_lengths(path.waypoints).sum()) / (path.speed * dt)
    if steps > MAX_STEPS:
        f.fail("motion", f"about {steps:.3g} steps of dt: too many (at most {MAX_STEPS:.0e})")
    return dt, jog, path


def _motion(f: Fields, motion: dict[str, Any]) -> tuple[tuple[JogSegment, ...], PathMotion | None]:
    if ("jog" in motion) == ("path" in motion):
        f.fail("motion", "give exactly one of [[motion.jog]] segments or a [motion.path]")
    if "jog" in motion:
        segments = []
        tables = f.tables(motion, "jog", "motion", ("duration", "velocity"))
        if not tables:
            f.fail("motion.jog", "needs at least one segment")
        for i, t in enumerate(tables):
            prefix = join("motion.jog", i)
            duration, velocity = f.number(t, "duration", prefix), f.vector(t, "velocity", prefix, 4)
            with f.mapped(prefix):
                segments.append(JogSegment(duration, velocity))
        return tuple(segments), None
    t = f.table(motion, "path", "motion", PATH_KEYS)
    raw = f.get(t, "waypoints", "motion.path")
    if not isinstance(raw, list) or len(raw) < 2:
        f.fail("motion.path.waypoints", "expected an array of at least 2 waypoints [l, z, h, α]")
    points = np.array(
        [f.vector_value(join("motion.path.waypoints", i), w, 4) for i, w in enumerate(raw)]
    )
    for i, h in enumerate(points[:, 2]):
        if h < 0:
            f.fail(f"motion.path.waypoints[{i}]", f"h = {h:g} m is inside the pipe (must be >= 0)")
    if not np.any(np.diff(points, axis=0) != 0.0):
        f.fail("motion.path.waypoints", "the waypoints are all the same: nothing to follow")
    speed = f.number(t, "speed", "motion.path")
    gain = f.number(t, "gain", "motion.path", 5.0)
    tol = f.number(t, "tolerance", "motion.path", 0.005)
    heading_tol = f.number(t, "heading_tolerance", "motion.path", 0.05)
    with f.mapped("motion.path"):
        _validate.positive("speed", speed)
        _validate.positive("gain", gain, strict=False)
        _validate.positive("tolerance", tol)
        _validate.positive("heading_tolerance", heading_tol)
    return (), PathMotion(_validate.readonly(points), speed, gain, tol, heading_tol)


def check_start(
    f: Fields, robot: Robot, q0: NDArray[np.float64], radius: float, obstacles: tuple[Obstacle, ...]
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
