"""Readers of the sections of a scene file: pipe, objective, constraints, motion.

The keys of ``[constraints]`` live on the limit classes that take them (``SCENE_KEYS``); the
sane range of each number is a :class:`~dvqp.scenes.fields.Bound` declared here
(``docs/scenes.md``, Ranges).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes.inlet import Inlet
from dvqp.kinematics.robot import Robot
from dvqp.limits import DEFAULT_QDD_MAX, Limit
from dvqp.limits.limit import SceneLimits
from dvqp.limits.registry import SCENE_LIMITS, constraint_keys
from dvqp.motion.jog import DEFAULT_RAMP, MAX_STEPS, JogSegment, default_gain, jog_step_count
from dvqp.motion.path import ToolPath
from dvqp.motion.saddle import SaddleWeld
from dvqp.motion.schedule import TIMINGS
from dvqp.objective import Objective
from dvqp.scenes.fields import Bound, Fields, join

PIPE_RADIUS = Bound(0.001, 100.0, "m")
POSITION = Bound(-1000.0, 1000.0, "m")
"""l or z of anything in the developed view (obstacles, the weld, waypoints)."""
HEADING = Bound(-1000.0, 1000.0, "rad")
HEIGHT = Bound(0.0, 10.0, "m")
SIZE = Bound(0.0, 100.0, "m", strict=True)
"""An obstacle's radius."""
WEIGHT = Bound(0.0, 1e6)
"""A weight or gain of the objective."""
GAIN = Bound(0.0, 1000.0, "1/s")
DT = Bound(0.0, 1.0, "s", strict=True)
RAMP = Bound(0.0, 10.0, "s")
JOINT_ACCELERATION = Bound(0.0, 1e4, "rad/s²", strict=True)
DURATION = Bound(0.0, 1e6, "s", strict=True)
SPEED = Bound(-10.0, 10.0, "m/s")
TURN_RATE = Bound(-10.0, 10.0, "rad/s")
TOLERANCE = Bound(0.0, 10.0, "m", strict=True)
HEADING_TOLERANCE = Bound(0.0, 10.0, "rad", strict=True)
OBJECTIVE_KEYS = ("orbital_level", "k_height", "k_obstacle", "gain")
PATH_KEYS = ("waypoints", "speed", "gain", "tolerance", "heading_tolerance", "timing")
FOLLOW_KEYS = PATH_KEYS[1:]
ONE_MOTION = "give exactly one of [[motion.jog]] segments, a [motion.path] or a [motion.saddle]"
SADDLE_KEYS = ("branch", "offset", "arc", "heading", "h", *FOLLOW_KEYS)


def pipe(f: Fields, doc: dict[str, Any]) -> tuple[float, float | None]:
    """``[pipe]``: the radius (m, > 0) and the optional weld z (m)."""
    pipe = f.table(doc, "pipe", "", ("radius", "weld"))
    radius = f.number(pipe, "radius", "pipe", within=PIPE_RADIUS)
    return radius, f.number(pipe, "weld", "pipe", within=POSITION) if "weld" in pipe else None


def orbital_level(f: Fields, doc: dict[str, Any]) -> float:
    """``objective.orbital_level``, m."""
    t = f.table(doc, "objective", "", OBJECTIVE_KEYS)
    return f.number(t, "orbital_level", "objective", within=HEIGHT)


def min_height(f: Fields, doc: dict[str, Any]) -> float | None:
    """``constraints.min_height``, m (None: the scene does not set it)."""
    t = f.table(doc, "constraints", "", constraint_keys(), required=False)
    return f.number(t, "min_height", "constraints") if "min_height" in t else None


def objective(f: Fields, doc: dict[str, Any], k: int, obstacles: ObstacleSet) -> Objective:
    """``[objective]`` for ``k`` body points: the paper's three terms with the obstacles."""
    t = f.table(doc, "objective", "", OBJECTIVE_KEYS)
    level = f.number(t, "orbital_level", "objective", within=HEIGHT)
    kh = f.vector(t, "k_height", "objective", k, scalar=True, default=1.0, within=WEIGHT)
    ko = f.vector(t, "k_obstacle", "objective", k, scalar=True, default=1.0, within=WEIGHT)
    gain = f.number(t, "gain", "objective", 1.0, within=WEIGHT)
    with f.mapped("objective"):
        return Objective.paper(level, obstacles, k_height=kh, k_obstacle=ko, gain=gain)


def limits(
    f: Fields, doc: dict[str, Any], robot: Robot, obstacles: ObstacleSet
) -> tuple[Limit, ...]:
    """Every limit of :data:`~dvqp.limits.registry.SCENE_LIMITS` the scene makes, in order:
    the joints' (``[robot]``), then the dampers of ``[constraints]`` (optional)."""
    keys = constraint_keys()
    t = f.table(doc, "constraints", "", keys, required=False)
    values = {key: f.number(t, key, "constraints") for key in keys if key in t}
    arm = doc.get("robot", {})
    qdd = f.vector(
        arm,
        "qdd_max",
        "robot",
        robot.n,
        scalar=True,
        default=DEFAULT_QDD_MAX,
        within=JOINT_ACCELERATION,
    )
    scene = SceneLimits(robot, obstacles, values, qdd)
    made = (_configured(f, cls, scene) for cls in SCENE_LIMITS)
    return tuple(limit for limit in made if limit is not None)


def _configured(f: Fields, cls: type[Limit], scene: SceneLimits) -> Limit | None:
    """``cls.from_scene(scene)``; errors name the scene key."""
    keys = cls.SCENE_KEYS
    try:
        return cls.from_scene(scene)
    except ParameterError as exc:
        field = next((key for key, param in keys.items() if param == exc.name), exc.name)
        f.fail(join("constraints", field), exc.reason)


def motion(
    f: Fields, doc: dict[str, Any], obstacles: ObstacleSet
) -> tuple[float, tuple[JogSegment, ...], ToolPath | None, float, SaddleWeld | None, float]:
    """``dt`` (s), the JOG segments or the path, the JOG ramp time (s), the saddle weld the
    path was made from (None: none) and the JOG's feedback gain (1/s)."""
    motion = f.table(doc, "motion", "", ("dt", "ramp", "gain", "jog", "path", "saddle"))
    dt = f.number(motion, "dt", "motion", within=DT)
    ramp = f.number(motion, "ramp", "motion", DEFAULT_RAMP, within=RAMP)
    if sum(kind in motion for kind in ("jog", "path", "saddle")) != 1:
        f.fail("motion", ONE_MOTION)
    if "gain" in motion and "jog" not in motion:
        kind = "path" if "path" in motion else "saddle"
        f.fail("motion.gain", f"a JOG's feedback gain; a {kind}'s is motion.{kind}.gain")
    tasks = doc.get("tasks") if isinstance(doc.get("tasks"), list) else []
    priorities = {t.get("priority", 1) for t in tasks if isinstance(t, dict)}
    default = default_gain(dt) if len(priorities) > 1 else 0.0  # one level: the paper's JOG
    gain = f.number(motion, "gain", "motion", default, within=GAIN)
    saddle = _saddle(f, motion, obstacles) if "saddle" in motion else None
    jog, path = ((), saddle[1]) if saddle else _motion(f, motion)
    steps = sum(s.duration for s in jog) / dt if path is None else path.step_count(dt)
    if steps <= MAX_STEPS and path is None:  # now the exact count cannot overflow
        steps = jog_step_count(jog, dt)
    if steps > MAX_STEPS:
        f.fail("motion", f"about {steps:.3g} steps of dt: too many (at most {MAX_STEPS:.0e})")
    return dt, jog, path, ramp, saddle[0] if saddle else None, gain


def _motion(f: Fields, motion: dict[str, Any]) -> tuple[tuple[JogSegment, ...], ToolPath | None]:
    if "jog" in motion:
        segments = []
        tables = f.tables(motion, "jog", "motion", ("duration", "velocity"))
        if not tables:
            f.fail("motion.jog", "needs at least one segment")
        for i, t in enumerate(tables):
            prefix = join("motion.jog", i)
            duration = f.number(t, "duration", prefix, within=DURATION)
            velocity = f.vector(t, "velocity", prefix, 4, within=(SPEED, SPEED, SPEED, TURN_RATE))
            with f.mapped(prefix):
                segments.append(JogSegment(duration, velocity))
        return tuple(segments), None
    t = f.table(motion, "path", "motion", PATH_KEYS)
    raw, wp = f.get(t, "waypoints", "motion.path"), "motion.path.waypoints"
    if not isinstance(raw, list) or len(raw) < 2:
        f.fail(wp, "expected an array of at least 2 waypoints [l, z, h, α]")
    bounds = (POSITION, POSITION, Bound(-1000.0, HEIGHT.high, "m"), HEADING)  # h < 0: below
    points = np.array([f.vector_value(join(wp, i), w, 4, within=bounds) for i, w in enumerate(raw)])
    for i, h in enumerate(points[:, 2]):
        if h < 0:
            f.fail(join(wp, i), f"h = {h:g} m is inside the pipe (must be >= 0)")
    if not np.any(np.diff(points, axis=0) != 0.0):
        f.fail(wp, "the waypoints are all the same: nothing to follow")
    speed, given = _following(f, t, "motion.path")
    return (), ToolPath(_validate.readonly(points), speed, **given)


def _following(f: Fields, t: dict[str, Any], prefix: str) -> tuple[float, dict[str, Any]]:
    """A path's ``speed`` (m/s) and its optional ``gain``, ``tolerance``, ``heading_tolerance``
    and ``timing``."""
    speed = f.number(t, "speed", prefix, within=Bound(0.0, SPEED.high, "m/s", True))
    optional = {"gain": GAIN, "tolerance": TOLERANCE, "heading_tolerance": HEADING_TOLERANCE}
    given: dict[str, Any] = {
        k: f.number(t, k, prefix, within=b) for k, b in optional.items() if k in t
    }
    if "timing" in t:
        given["timing"] = f.string(t, "timing", prefix)
        if given["timing"] not in TIMINGS:
            f.fail(
                join(prefix, "timing"),
                f"must be one of {', '.join(TIMINGS)}, got {given['timing']!r}",
            )
    return speed, given


def _saddle(
    f: Fields, motion: dict[str, Any], obstacles: ObstacleSet
) -> tuple[SaddleWeld, ToolPath]:
    """``[motion.saddle]``: the weld round a branch (a named ``inlet`` obstacle) and its path."""
    t, prefix = f.table(motion, "saddle", "motion", SADDLE_KEYS), "motion.saddle"
    name = f.string(t, "branch", prefix)
    pairs = zip(obstacles.labels, obstacles.obstacles, strict=True)
    inlets = {label: shape for label, shape in pairs if isinstance(shape, Inlet)}
    if name not in inlets:
        known = ", ".join(repr(k) for k in inlets if not k.startswith("obstacles[")) or "none"
        f.fail(join(prefix, "branch"), f"no inlet obstacle named {name!r} (named inlets: {known})")
    branch = inlets[name]
    offset = f.number(t, "offset", prefix, within=Bound(0.0, SIZE.high, "m"))
    arc = f.vector(t, "arc", prefix, 2, default=[-0.5 * np.pi, 1.5 * np.pi], within=HEADING)
    heading = f.string(t, "heading", prefix, "along")
    height = f.number(t, "h", prefix, within=HEIGHT)
    speed, given = _following(f, t, prefix)
    with f.mapped(prefix):
        weld = SaddleWeld(
            branch.center,
            branch.radius,
            branch.pipe_radius,
            offset,
            (float(arc[0]), float(arc[1])),
            heading,
            height,
        )
        return weld, weld.path(speed, **given)
