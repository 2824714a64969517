"""``[[tasks]]`` of a scene file: the hard tasks, each of a kind, at a priority.

Each table has a ``kind`` (``tool``, ``point``, ``posture``, ``frame``), an integer ``priority``
(>= 1, 1 the highest; tasks of one priority form one level) and a ``weight`` within its level,
and the keys of its kind (``docs/scenes.md``). Every key is checked like any field of a scene:
an unknown kind or component, a priority that is not an integer >= 1, a point index out of
range, an unknown frame (the message lists the model's frames), an empty component list, and
a level that cannot be met even alone at the start (more rows than joints, or dependent rows)
are refused with ``<file>: tasks[i].<key>: <reason>``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from dvqp.errors import ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.motion.jog import JogSegment
from dvqp.motion.path import ToolPath
from dvqp.resolution.spec import StepSpec, unmeetable
from dvqp.scenes.fields import Bound, Fields, join
from dvqp.tasks import FrameTask, PointTask, PostureTask, Task, ToolTask
from dvqp.tasks.frame import COMPONENTS as FRAME_COMPONENTS
from dvqp.tasks.point import COMPONENTS as POINT_COMPONENTS
from dvqp.tasks.point import point_index
from dvqp.tasks.task import check_priority
from dvqp.tasks.tool_dv import COMPONENTS as TOOL_COMPONENTS

KINDS = ("tool", "point", "posture", "frame")
COMMON = ("kind", "priority", "weight")
KEYS = {
    "tool": (*COMMON, "components"),
    "point": (*COMMON, "point", "components", "target", "gain"),
    "posture": (*COMMON, "target", "gain"),
    "frame": (*COMMON, "frame", "components", "position", "rpy", "gain"),
}
"""The keys each kind of task takes."""
WEIGHT = Bound(0.0, 1e6, strict=True)
GAIN = Bound(0.0, 1000.0, "1/s")
POSITION = Bound(-1000.0, 1000.0, "m")
ANGLE = Bound(-1000.0, 1000.0, "rad")

Reader = Callable[[Fields, dict[str, Any], str, Robot, np.ndarray, KinematicState], Task]


def tasks(
    f: Fields, doc: dict[str, Any], robot: Robot, q0: np.ndarray, radius: float
) -> tuple[Task, ...]:
    """The scene's ``[[tasks]]`` (empty: none given, the tool's DV task alone)."""
    tables = f.tables(doc, "tasks", "", sorted({k for keys in KEYS.values() for k in keys}))
    if not tables:
        return ()
    start = KinematicState.compute(robot, q0, radius)
    made: list[Task] = []
    for i, t in enumerate(tables):
        prefix = join("tasks", i)
        kind = f.string(t, "kind", prefix)
        if kind not in KINDS:
            f.fail(join(prefix, "kind"), f"unknown kind {kind!r} (known: {', '.join(KINDS)})")
        f.check_keys(t, prefix, KEYS[kind])
        with f.mapped(prefix):
            made.append(READERS[kind](f, t, prefix, robot, q0, start))
    _distinct_tool_components(f, tables)
    _levels_met(f, made, start)
    return tuple(made)


def check_followed(
    f: Fields,
    tasks: Sequence[Task],
    jog: Sequence[JogSegment],
    path: ToolPath | None,
    tool0: np.ndarray,
) -> None:
    """Refuse a motion that commands a tool component no task follows (:attr:`Task.follows`;
    no ``[[tasks]]``: the tool's task, all four): a JOG segment's non-zero velocity, or a
    path's waypoints (with the tool's start ``tool0`` (4,)) changing in it."""
    followed = {c for task in tasks for c in task.follows} if tasks else set(TOOL_COMPONENTS)
    names = "; ".join(task.label for task in tasks)
    for i, segment in enumerate(jog):
        moved = [c for c, v in zip(TOOL_COMPONENTS, segment.velocity, strict=True) if v != 0.0]
        unused = [c for c in moved if c not in followed]
        if unused:
            f.fail(
                join(join("motion.jog", i), "velocity"),
                f"commands the tool's {', '.join(unused)} but no task follows "
                f"{'it' if len(unused) == 1 else 'them'} (tasks: {names}); add a "
                f'[[tasks]] kind = "tool" with components = {unused!r} or command 0 there',
            )
    if path is not None:
        nodes = np.vstack([tool0, path.waypoints])
        moved = [
            c for c, span in zip(TOOL_COMPONENTS, np.ptp(nodes, axis=0), strict=True) if span > 1e-9
        ]
        unused = [c for c in moved if c not in followed]
        if unused:
            f.fail(
                "motion.path.waypoints",
                f"move the tool's {', '.join(unused)} but no task follows "
                f"{'it' if len(unused) == 1 else 'them'} (tasks: {names}); add a "
                f'[[tasks]] kind = "tool" with components = {unused!r}',
            )


def _common(f: Fields, t: dict[str, Any], prefix: str) -> dict[str, Any]:
    """``priority`` (an integer >= 1) and ``weight`` (> 0)."""
    raw = f.get(t, "priority", prefix, 1)
    try:
        priority = check_priority(raw)
    except ParameterError as exc:
        f.fail(join(prefix, "priority"), exc.reason)
    return {"priority": priority, "weight": f.number(t, "weight", prefix, 1.0, within=WEIGHT)}


def _components(t: dict[str, Any], default: tuple[str, ...]) -> Any:
    """``components`` as written (checked by the task), or the kind's default."""
    return t.get("components", default)


def _tool(
    f: Fields, t: dict[str, Any], prefix: str, robot: Robot, q0: np.ndarray, start: KinematicState
) -> Task:
    return ToolTask(_components(t, TOOL_COMPONENTS), **_common(f, t, prefix))


def _point(
    f: Fields, t: dict[str, Any], prefix: str, robot: Robot, q0: np.ndarray, start: KinematicState
) -> Task:
    given = f.get(t, "point", prefix)
    names = robot.part_names.points[: robot.n_points]
    if isinstance(given, bool) or not isinstance(given, (int, str)):
        f.fail(
            join(prefix, "point"),
            f"expected an index (0-based) or a name ({names[0]!r}, as reports say), got {given!r}",
        )
    try:
        raw = point_index(given, names)
    except ParameterError as exc:
        f.fail(join(prefix, "point"), exc.reason)
    if not 0 <= raw < robot.n_points:
        f.fail(
            join(prefix, "point"),
            f"index {raw} is out of range: the arm has body points 0 .. {robot.n_points - 1}",
        )
    common = _common(f, t, prefix)
    task = PointTask(raw, _components(t, POINT_COMPONENTS), **common)
    target = np.array(start.points[raw])
    if "target" in t:
        value, count, field = t["target"], len(task.components), join(prefix, "target")
        length = len(value) if isinstance(value, list) else -1
        if length not in (count, 3):
            names = ", ".join(task.components)
            f.fail(field, f"expected {count} numbers ({names}) or 3 ([l, z, h]), got {value!r}")
        given = f.vector_value(field, value, length, within=POSITION)
        if length == 3:
            target = given
        else:
            target[task.index] = given
    gain = f.number(t, "gain", prefix, task.gain, within=GAIN)
    return PointTask(raw, task.components, target, gain=gain, **common)


def _posture(
    f: Fields, t: dict[str, Any], prefix: str, robot: Robot, q0: np.ndarray, start: KinematicState
) -> Task:
    common = _common(f, t, prefix)
    target = f.vector(t, "target", prefix, robot.n, default=list(q0), within=ANGLE)
    gain = f.number(t, "gain", prefix, PostureTask().gain, within=GAIN)
    return PostureTask(target, gain=gain, **common)


def _frame(
    f: Fields, t: dict[str, Any], prefix: str, robot: Robot, q0: np.ndarray, start: KinematicState
) -> Task:
    name = f.string(t, "frame", prefix)
    common = _common(f, t, prefix)
    task = FrameTask(robot, name, _components(t, FRAME_COMPONENTS), **common)
    origin, rotation = task.pose(q0)
    if "position" in t:
        origin = f.vector(t, "position", prefix, 3, within=POSITION)
    if "rpy" in t:
        rpy = f.vector(t, "rpy", prefix, 3, within=ANGLE)
        rotation = pin.rpy.rpyToMatrix(*rpy)
    gain = f.number(t, "gain", prefix, task.gain, within=GAIN)
    return FrameTask(
        robot, name, task.components, position=origin, rotation=rotation, gain=gain, **common
    )


READERS: dict[str, Reader] = {"tool": _tool, "point": _point, "posture": _posture, "frame": _frame}


def _distinct_tool_components(f: Fields, tables: list[dict[str, Any]]) -> None:
    """A tool component held by two ``tool`` tables is refused (its rows would repeat)."""
    held: dict[str, int] = {}
    for i, t in enumerate(tables):
        if t["kind"] != "tool":
            continue
        for c in _components(t, TOOL_COMPONENTS):
            if c in held:
                f.fail(
                    join(join("tasks", i), "components"),
                    f"{c!r} is already held by tasks[{held[c]}]",
                )
            held[c] = i


def _levels_met(f: Fields, made: list[Task], start: KinematicState) -> None:
    """Each level can be met alone at the start (:func:`~dvqp.resolution.spec.unmeetable`)."""
    try:
        spec_levels = StepSpec(tuple(made)).levels
    except ParameterError as exc:  # too many levels
        f.fail("tasks", exc.reason)
    for number, level in enumerate(spec_levels, start=1):
        rows = [task.compute(start, np.zeros(4), 0.0).jacobian for task in level]
        reason = unmeetable(np.vstack(rows))
        if reason is not None:
            first = next(i for i, task in enumerate(made) if task is level[0])
            names = "; ".join(task.label for task in level)
            f.fail(
                join("tasks", first),
                f"level {number} ({names}) cannot be met even alone: {reason}",
            )
