"""Random obstacles of every shape around the weld and the arm, never over the start.

Each obstacle is drawn as a scene file's ``[[obstacles]]`` table, read as the scene loader
reads it, and kept only if every guarded part of the arm starts at least ``margin + START_GAP``
from it; else it is drawn again (at most :data:`TRIES` times, then left out). The distribution
is documented in ``docs/bench.md``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.bench.toml_text import Table
from dvqp.errors import DvqpError
from dvqp.geometry import min_clearance
from dvqp.kinematics import KinematicState
from dvqp.scenes.fields import Fields
from dvqp.scenes.obstacles import obstacles as read_obstacles

SHAPE_ORDER = ("circle", "inlet", "band", "polygon")
"""The shapes drawn; scene i's first obstacle is ``SHAPE_ORDER[i % 4]``."""
START_GAP = 0.003
"""Clearance beyond the margin every guarded part keeps from a new obstacle at the start, m."""
TRIES = 40
"""Draws of one obstacle before it is left out."""


@dataclass(frozen=True)
class Start:
    """What the obstacles are placed around: the arm's ``state`` at ``q0``, the ``weld``'s z
    (m), the scene's obstacle ``margin`` (m), whether to keep circles, inlets and polygons off
    the weld line (``beside_weld``: a path follows it) and the ``track``, ``[l, z]`` (m) of
    the tool's commanded motion (:func:`dvqp.bench.motion.tool_track`)."""

    state: KinematicState
    weld: float
    margin: float
    beside_weld: bool
    track: NDArray[np.float64]


def draw_obstacles(rng: np.random.Generator, start: Start, first: str) -> list[Table]:
    """One to four obstacles, the first of shape ``first``, the others of any shape."""
    count = int(rng.integers(1, 5))
    kinds = [first, *(str(k) for k in rng.choice(SHAPE_ORDER, size=count - 1))]
    out = []
    for kind in kinds:
        for _ in range(TRIES):
            table = DRAW[kind](rng, start)
            if start_clearance(table, start) >= start.margin + START_GAP:
                out.append(table)
                break
    return out


def start_clearance(table: Table, start: Start) -> float:
    """Smallest start clearance (m) of the arm's guarded parts to one obstacle table, read by
    the scene loader; a table it refuses counts as ``-inf`` (drawn again)."""
    try:
        obstacle = read_obstacles(Fields("<bench>"), {"obstacles": [table]}, start.state.radius)
    except DvqpError:
        return -np.inf
    return min_clearance(start.state, obstacle)


def _mm(value: float) -> float:
    """Rounded to 0.1 mm (positions and sizes in the file)."""
    return round(float(value), 4)


def _weight(rng: np.random.Generator) -> float:
    return round(float(rng.uniform(10.0, 30.0)), 1)


def _on_track(rng: np.random.Generator, start: Start, size: float) -> tuple[float, float]:
    """A centre by the tool's commanded track: across it (JOG) or beside it (a path)."""
    track = start.track
    k = int(rng.integers(0, track.shape[0] - 1))
    point = track[k] + rng.uniform(0.3, 1.0) * (track[k + 1] - track[k])
    if start.beside_weld:
        side = rng.choice((-1.0, 1.0)) * (size + start.margin + rng.uniform(0.005, 0.03))
        return float(point[0]), float(point[1] + side)
    angle, gap = rng.uniform(0.0, 2.0 * np.pi), size + rng.uniform(-0.01, 0.02)
    return point[0] + gap * np.cos(angle), point[1] + gap * np.sin(angle)


def _anchor(rng: np.random.Generator, start: Start, size: float) -> tuple[float, float]:
    """A centre by the tool's track (2 in 5), by the weld (3 in 10) or by the arm (3 in 10)."""
    guarded = start.state.guarded
    pick = rng.random()
    if pick < 0.4:
        return _on_track(rng, start, size)
    if pick < 0.7:
        l = guarded[-1, 0] + rng.choice((-1.0, 1.0)) * rng.uniform(0.06, 0.30)
        if start.beside_weld:
            z = start.weld + rng.choice((-1.0, 1.0)) * (size + rng.uniform(0.02, 0.05))
        else:
            z = start.weld + rng.uniform(-0.06, 0.06)
        return l, z
    part = guarded[int(rng.integers(1, guarded.shape[0]))]
    angle, gap = rng.uniform(0.0, 2.0 * np.pi), size + rng.uniform(0.015, 0.06)
    return part[0] + gap * np.cos(angle), part[1] + gap * np.sin(angle)


def _round(rng: np.random.Generator, start: Start, kind: str) -> Table:
    """A circle or an inlet."""
    radius = rng.uniform(0.025, 0.07)
    l, z = _anchor(rng, start, radius)
    return {
        "shape": kind,
        "center": [_mm(l), _mm(z)],
        "radius": _mm(radius),
        "weight": _weight(rng),
    }


def _band(rng: np.random.Generator, start: Start) -> Table:
    """A band above the arm's highest part (3 in 4) or below its lowest."""
    z = start.state.guarded[:, 1]
    width = rng.uniform(0.02, 0.05)
    if rng.random() < 0.75:
        low = z.max() + rng.uniform(0.03, 0.12)
        return {"shape": "band", "z": [_mm(low), _mm(low + width)], "weight": _weight(rng)}
    high = z.min() - rng.uniform(0.03, 0.08)
    return {"shape": "band", "z": [_mm(high - width), _mm(high)], "weight": _weight(rng)}


def _polygon(rng: np.random.Generator, start: Start) -> Table:
    """A star-shaped polygon (3 to 6 vertices at increasing angles: always simple)."""
    n = int(rng.integers(3, 7))
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, size=n))
    angles += np.arange(n) * 1e-3  # strictly increasing
    radii = rng.uniform(0.02, 0.05, size=n)
    l, z = _anchor(rng, start, float(radii.max()))
    vertices = [
        [_mm(l + r * np.cos(a)), _mm(z + r * np.sin(a))] for a, r in zip(angles, radii, strict=True)
    ]
    return {"shape": "polygon", "vertices": vertices, "weight": _weight(rng)}


DRAW = {
    "circle": functools.partial(_round, kind="circle"),
    "inlet": functools.partial(_round, kind="inlet"),
    "band": _band,
    "polygon": _polygon,
}
"""One drawing function per shape of :data:`SHAPE_ORDER`."""
