"""Seeded random scenes for ``dvqp bench``: one deterministic stream per scene.

Scene ``i`` of seed ``s`` is drawn from ``np.random.default_rng([s, i])`` alone, so it is the
same whatever the count, the workers or the machine. A draw is kept only if
:func:`dvqp.scenes.loads` accepts its text, the arm starts clear of every obstacle by the
margin and the run has 10 to ``2 * MAX_STEPS`` steps; else it is drawn again from the same
stream. The distribution is documented in ``docs/bench.md``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from dvqp._files import atomic_file
from dvqp.bench.motion import DT_CHOICES, MAX_STEPS, draw_jog, draw_path, tool_track
from dvqp.bench.obstacles import SHAPE_ORDER, Start, draw_obstacles
from dvqp.bench.toml_text import Table, dumps
from dvqp.errors import DvqpError, ParameterError
from dvqp.geometry import min_clearance
from dvqp.kinematics import KinematicState, Robot
from dvqp.run.planning import scene_commands
from dvqp.scenes import Scene, loads

PIPE_RADIUS = 0.254
"""R of every generated scene, m (the bundled scenes' pipe)."""
LINK_LENGTHS = (0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06)
"""The bundled NDT arm's link lengths, m."""
Q0 = (
    1.5708,
    -0.048,
    0.068,
    0.026,
    0.08,
    0.032,
    0.088,
    -0.078,
    -0.088,
    0.003,
    -0.434,
    0.116,
    -0.278,
)
"""The bundled start configuration the generated ones vary around, rad."""
ATTEMPTS = 100
"""Draws of one scene before giving up (never reached in practice)."""


@dataclass(frozen=True)
class BenchScene:
    """A generated scene: drawn from ``default_rng([seed, index])``, named
    ``bench-s<seed>-<index:04d>``, its scene file's ``text``, its ``mode`` (``"jog"`` or
    ``"path"``), its obstacles' ``shapes`` in file order, its step ``dt`` (s) and the
    ``steps`` of one run."""

    seed: int
    index: int
    name: str
    text: str
    mode: str
    shapes: tuple[str, ...]
    dt: float
    steps: int

    @property
    def file_name(self) -> str:
        """``bench-s11-0007.toml``."""
        return f"{self.name}.toml"


def scene_name(seed: int, index: int) -> str:
    """``bench-s11-0007``: the name of scene ``index`` of ``seed``."""
    return f"bench-s{seed}-{index:04d}"


@functools.lru_cache(maxsize=1)
def _robot() -> Robot:
    return Robot.ndt13(LINK_LENGTHS)


def generate_scene(seed: int, index: int) -> BenchScene:
    """Scene ``index`` of ``seed`` (independent of any other scene); ParameterError if ``seed``
    or ``index`` is negative, or no acceptable scene comes in :data:`ATTEMPTS` draws."""
    if seed < 0 or index < 0:
        raise ParameterError("seed", f"seed and index must be >= 0, got {seed}, {index}")
    rng = np.random.default_rng([seed, index])
    name = scene_name(seed, index)
    for _ in range(ATTEMPTS):
        doc = _draw(rng, seed, index)
        if doc is None:
            continue
        text = dumps(doc, f"dvqp bench --seed {seed}: scene {index}\n`dvqp plan` reproduces it")
        try:
            scene = loads(text, f"{name}.toml")
        except DvqpError:
            continue
        steps = _accepted_steps(scene, float(doc["constraints"]["margin"]))
        if steps is not None:
            shapes = tuple(str(o["shape"]) for o in doc["obstacles"])
            return BenchScene(seed, index, name, text, scene.mode, shapes, scene.dt, steps)
    raise ParameterError("seed", f"no acceptable scene {index} of seed {seed} in {ATTEMPTS} draws")


def generate_scenes(seed: int, count: int) -> list[BenchScene]:
    """Scenes ``0 .. count-1`` of ``seed``."""
    if count < 1:
        raise ParameterError("count", f"must be >= 1, got {count}")
    return [generate_scene(seed, i) for i in range(count)]


def _accepted_steps(scene: Scene, margin: float) -> int | None:
    """The run's steps if the scene is acceptable (start clear of the obstacles), else None."""
    state = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius)
    if min_clearance(state, scene.obstacles) < margin:
        return None
    steps = int(scene_commands(scene).velocity.shape[0])
    return steps if 10 <= steps <= 2 * MAX_STEPS else None


def _draw(rng: np.random.Generator, seed: int, index: int) -> Table | None:
    """One draw of the whole scene as a TOML document (None: its start is unusable)."""
    q0 = _draw_q0(rng)
    try:
        state = KinematicState.compute(_robot(), q0, PIPE_RADIUS)
    except DvqpError:
        return None
    if np.any(state.guarded[:, 2] < 0.0):
        return None
    constraints = _draw_constraints(rng)
    tool = state.tool
    weld = round(float(tool[1]), 4)
    dt = float(rng.choice(DT_CHOICES))
    path = rng.random() < 0.5
    motion = draw_path(rng, tool, dt) if path else draw_jog(rng, dt)
    start = Start(state, weld, constraints["margin"], path, tool_track(motion, tool))
    obstacles = draw_obstacles(rng, start, SHAPE_ORDER[index % len(SHAPE_ORDER)])
    kinds = ", ".join(str(o["shape"]) for o in obstacles)
    return {
        "name": scene_name(seed, index),
        "description": f"random {'weld path' if path else 'JOG'} scene, dt {dt} s, "
        f"obstacles: {kinds}",
        "pipe": {"radius": PIPE_RADIUS, "weld": weld},
        "robot": {
            "model": "ndt13",
            "link_lengths": list(LINK_LENGTHS),
            "q0": [round(float(q), 4) for q in q0],
        },
        "objective": {"orbital_level": 0.08, "k_height": 100.0, "k_obstacle": 1.0, "gain": 1.0},
        "obstacles": obstacles,
        "constraints": constraints,
        "motion": motion,
    }


def _draw_q0(rng: np.random.Generator) -> NDArray[np.float64]:
    """The bundled start, the carriage turned by up to ±0.2 rad, each arm joint moved by a
    normal draw of σ = 0.03 rad clipped to ±0.06 rad; rounded to 0.1 mrad."""
    q0 = np.array(Q0)
    q0[0] += rng.uniform(-0.2, 0.2)
    q0[1:] += np.clip(rng.normal(0.0, 0.03, size=q0.shape[0] - 1), -0.06, 0.06)
    return np.round(q0, 4)


def _draw_constraints(rng: np.random.Generator) -> dict[str, float]:
    """``[constraints]``: margin 5–15 mm, influence 4–6 cm beyond it, minimum height 1–3 cm,
    damper gain 0.3–0.7, minimum tilt 0.1–0.3 rad."""
    margin = round(float(rng.uniform(0.005, 0.015)), 4)
    return {
        "min_height": round(float(rng.uniform(0.01, 0.03)), 4),
        "margin": margin,
        "influence": round(margin + float(rng.uniform(0.04, 0.06)), 4),
        "damper_gain": round(float(rng.uniform(0.3, 0.7)), 3),
        "min_tilt": round(float(rng.uniform(0.1, 0.3)), 3),
    }


def save_scenes(scenes: list[BenchScene], folder: Path) -> list[Path]:
    """Write each scene as ``folder/<name>.toml`` (atomically; the folder must exist)."""
    written = []
    for scene in scenes:
        target = folder / scene.file_name
        with atomic_file(target) as tmp:
            tmp.write_text(scene.text, encoding="utf-8")
        written.append(target)
    return written
