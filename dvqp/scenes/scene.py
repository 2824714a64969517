"""Scene files: a pipe, an arm, the objective, obstacles, limits and a motion, in TOML.

:func:`load_scene` reads a ``.toml`` file (``tomllib``, or ``tomli`` on Python 3.10) into a
:class:`Scene` of typed objects. Anything wrong, or anything else that escapes the checks (a
parser's recursion limit, an overflow), raises :class:`~dvqp.errors.SceneError`:
``<file>: <field>: <reason>``, the field a dotted TOML path with 0-based array indices
(``obstacles[1].radius``). The format is documented in ``docs/scenes.md``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp._inputs import read_bounded
from dvqp.errors import InputFileError, SceneError, one_line
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits import Limit
from dvqp.motion.jog import JogSegment
from dvqp.motion.path import ToolPath
from dvqp.motion.saddle import SaddleWeld
from dvqp.objective import Objective
from dvqp.resolution.spec import StepSpec
from dvqp.scenes import obstacles as obstacle_section
from dvqp.scenes import robot_section, start, tasks_section
from dvqp.scenes import sections as sec
from dvqp.scenes.fields import Fields
from dvqp.scenes.solver_options import solver_options
from dvqp.tasks import Task, ToolTask

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

__all__ = ["Environment", "Scene", "environment", "load_scene", "loads"]

TOP_KEYS = (
    "name",
    "description",
    "pipe",
    "robot",
    "objective",
    "obstacles",
    "constraints",
    "motion",
    "solvers",
    "tasks",
)
"""The keys a scene file may have at its top level."""
MAX_BYTES = 1 << 24
"""Largest scene file read, bytes (16 MiB; the bundled scenes take 1 to 3 kB)."""


@dataclass(frozen=True)
class Scene:
    """A validated scene (see ``docs/scenes.md`` for the file format).

    Attributes
    ----------
    name, description : str
        Labels (``name`` defaults to the file's stem).
    source, text : str
        The file it came from (or ``"<string>"``) and its TOML text (stored in trajectories).
    pipe_radius, weld : float, float or None
        ``R`` and the z of the circumferential weld (for plots), m.
    robot : Robot
        The arm with its limits.
    q0, weights : ndarray, shape (n,)
        Start configuration (rad) and the diagonal of ``W``.
    orbital_level : float
        ``h*``, m.
    obstacles : ObstacleSet
        The obstacles (shared by the objective, the dampers and the diagnostics).
    objective : Objective
        ``w(Q)``: the paper's three terms.
    limits : tuple of Limit
        Joint position, velocity and acceleration limits, then those of ``[constraints]``.
    jog, path : tuple of JogSegment, ToolPath or None
        The JOG segments (empty in path mode) or the path to follow (None in JOG mode).
    dt, ramp : float
        The step, and the time JOG velocity changes are spread linearly over (0: steps), s.
    solver_options : dict of str to dict
        ``[solvers.<backend>]``: settings handed to that QP backend when the scene runs on it.
    saddle : SaddleWeld or None
        ``[motion.saddle]``: the weld curve round a branch that ``path`` was sampled from.
    tasks : tuple of Task
        ``[[tasks]]``: the hard tasks at their priorities; empty (no ``[[tasks]]``): the tool's
        DV task, all four components, alone (the paper's).
    jog_gain : float
        ``[motion] gain``, 1/s: the feedback a JOG closes on its reference (the start plus the
        integrated commands; default ``0.5 / dt`` with tasks at more than one priority); 0 (the
        default of one level): the paper's JOG, velocities only.
    """

    name: str
    description: str
    source: str
    text: str = field(repr=False)
    pipe_radius: float
    weld: float | None
    robot: Robot = field(repr=False)
    q0: NDArray[np.float64] = field(repr=False)
    weights: NDArray[np.float64] = field(repr=False)
    orbital_level: float
    obstacles: ObstacleSet = field(repr=False)
    objective: Objective = field(repr=False)
    limits: tuple[Limit, ...] = field(repr=False)
    dt: float
    jog: tuple[JogSegment, ...] = field(repr=False)
    path: ToolPath | None = field(repr=False)
    ramp: float = 0.0
    solver_options: dict[str, dict[str, Any]] = field(default_factory=dict, repr=False)
    saddle: SaddleWeld | None = field(default=None, repr=False)
    tasks: tuple[Task, ...] = field(default=(), repr=False)
    jog_gain: float = 0.0

    def spec(self) -> StepSpec:
        """The step of this scene: its tasks (the tool's DV task if it names none), the
        objective, the limits, ``W``."""
        tasks = self.tasks or (ToolTask(),)
        return StepSpec(tasks, self.objective, self.limits, self.weights)

    @property
    def mode(self) -> str:
        """``"jog"`` or ``"path"``."""
        return "jog" if self.path is None else "path"


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; relative URDF paths resolve from its folder.

    Raises
    ------
    SceneError
        ``<path>: <field>: <reason>`` for an unreadable or invalid file, or one larger than
        :data:`MAX_BYTES`.
    """
    try:
        data = read_bounded(path, MAX_BYTES, "a scene file")
        text = data.decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")
    except InputFileError as exc:
        raise SceneError(str(path), "", exc.reason) from exc
    except UnicodeDecodeError as exc:
        raise SceneError(str(path), "", f"cannot read: {exc}") from exc
    return loads(text, source=str(path), base_dir=Path(path).parent)


def loads(text: str, source: str = "<string>", *, base_dir: str | Path | None = None) -> Scene:
    """Parse and validate scene TOML ``text``; ``source`` names it in error messages, and
    relative URDF paths resolve from ``base_dir`` (default: ``source``'s folder if it names a
    file, else the working directory)."""
    f = Fields(source)
    doc = _parse(f, text)
    if base_dir is None:
        base_dir = Path.cwd() if source.startswith("<") else Path(source).parent
    with f.guard("pipe"):
        radius, weld = sec.pipe(f, doc)
    with f.guard("robot"):
        robot, q0, weights = robot_section.robot(f, doc, Path(base_dir))
    with f.guard("obstacles"):
        obstacles = obstacle_section.obstacles(f, doc, radius)
    with f.guard("objective"):
        objective = sec.objective(f, doc, robot.n_points, obstacles)
        level = sec.orbital_level(f, doc)
    with f.guard("constraints"):
        limits = sec.limits(f, doc, robot, obstacles)
    with f.guard("motion"):
        dt, jog, path, ramp, saddle, jog_gain = sec.motion(f, doc, obstacles)
    with f.guard("solvers"):
        options = solver_options(f, doc)
    with f.guard("robot.q0"):
        start.check_start(f, robot, q0, radius, obstacles)
    with f.guard("tasks"):
        tasks = tasks_section.tasks(f, doc, robot, q0, radius)
    with f.guard("motion"):
        tool0 = KinematicState.compute(robot, q0, radius).tool
        tasks_section.check_followed(f, tasks, jog, path, tool0)
    with f.guard("constraints"):
        start.check_floor(f, robot, q0, radius, limits)
    stem = "scene" if source.startswith("<") else Path(source).stem
    return Scene(
        name=one_line(f.string(doc, "name", "", stem)),
        description=one_line(f.string(doc, "description", "", "")),
        source=source,
        text=text,
        pipe_radius=radius,
        weld=weld,
        robot=robot,
        q0=q0,
        weights=weights,
        orbital_level=level,
        obstacles=obstacles,
        objective=objective,
        limits=limits,
        dt=dt,
        jog=jog,
        path=path,
        ramp=ramp,
        solver_options=options,
        saddle=saddle,
        tasks=tasks,
        jog_gain=jog_gain,
    )


@dataclass(frozen=True)
class Environment:
    """What a plot needs of a scene: the pipe, the orbital level, the weld, the obstacles and
    ``min_height`` (None: not set)."""

    pipe_radius: float
    orbital_level: float
    weld: float | None
    obstacles: ObstacleSet
    min_height: float | None = None


def environment(text: str, source: str = "<string>") -> Environment:
    """Read only the pipe, objective, obstacles and ``min_height`` of scene text (no robot is
    built).

    For a trajectory's stored scene, whose URDF may no longer be where it was.
    """
    f = Fields(source)
    doc = _parse(f, text)
    with f.guard("pipe"):
        radius, weld = sec.pipe(f, doc)
    with f.guard("objective"):
        level = sec.orbital_level(f, doc)
    with f.guard("constraints"):
        floor = sec.min_height(f, doc)
    with f.guard("obstacles"):
        return Environment(radius, level, weld, obstacle_section.obstacles(f, doc, radius), floor)


def _parse(f: Fields, text: str) -> dict[str, Any]:
    """The TOML document; whatever the parser raises becomes ``invalid TOML: <reason>``."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        f.fail("", f"invalid TOML: {exc}")
    except RecursionError:  # arrays or inline tables nested some hundreds of levels deep
        f.fail("", "invalid TOML: values nested too deeply")
    except ValueError as exc:  # e.g. an integer of more than 4300 digits
        f.fail("", f"invalid TOML: {str(exc).split(';')[0]}")
    f.check_keys(doc, "", TOP_KEYS)
    return doc
