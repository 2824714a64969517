"""Random motions, drawn as a scene file's ``[motion]`` table: operator JOG sequences and paths
along the weld, their durations scaled down or speed raised to fit in :data:`MAX_STEPS` steps.
The distribution is documented in ``docs/bench.md``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from dvqp.bench.toml_text import Table
from dvqp.motion import ToolPath

DT_CHOICES = (0.005, 0.01, 0.02)
"""Step sizes drawn from, s."""
MAX_STEPS = 240
"""Most steps of a generated run."""
JOG_KINDS = (
    ((0, 0.03, 0.08),),  # along the weld
    ((1, 0.02, 0.05),),  # along the pipe
    ((3, 0.2, 0.6),),  # a turn
    ((2, 0.005, 0.015),),  # up or down
    ((0, 0.02, 0.06), (1, 0.02, 0.04), (3, 0.0, 0.3)),  # a diagonal
)
"""Kinds of JOG segment: (axis of ``[l̇, ż, ḣ, α̇]``, low, high) of each speed (m/s, rad/s)."""


def _r(value: float, digits: int = 4) -> float:
    return round(float(value), digits)


def _sign(rng: np.random.Generator) -> float:
    return float(rng.choice((-1.0, 1.0)))


def _jog_velocity(rng: np.random.Generator) -> list[float]:
    """``[l̇, ż, ḣ, α̇]`` of one segment of a random kind: each speed uniform, of either sign."""
    v = [0.0, 0.0, 0.0, 0.0]
    for axis, low, high in JOG_KINDS[int(rng.integers(0, len(JOG_KINDS)))]:
        v[axis] = _sign(rng) * rng.uniform(low, high)
    return [_r(x) for x in v]


def draw_jog(rng: np.random.Generator, dt: float) -> Table:
    """One to four JOG segments of 0.3 to 1.0 s (scaled down to :data:`MAX_STEPS` steps)."""
    count = int(rng.integers(1, 5))
    durations = rng.uniform(0.3, 1.0, size=count)
    scale = min(1.0, MAX_STEPS * dt / float(durations.sum()))
    segments = [
        {"duration": _r(max(d * scale, 5 * dt), 3), "velocity": _jog_velocity(rng)}
        for d in durations
    ]
    return {"dt": dt, "jog": segments}


def draw_path(rng: np.random.Generator, tool: NDArray[np.float64], dt: float) -> Table:
    """A path along the weld from the tool's start: two to four waypoints.

    The first lies within 5 mm of the tool; each next one moves 4 to 12 cm along the weld
    (one direction), with a raster offset of up to 15 mm in z half of the time, up to 5 mm
    in h, and a heading change of up to 0.3 rad a third of the time. Speed 5 to 12 cm/s,
    raised if needed so the run fits in :data:`MAX_STEPS` steps.
    """
    l0, z0, h0, a0 = (float(x) for x in tool)
    first = [l0 + rng.uniform(-0.005, 0.005), z0, h0, a0]
    points, direction = [first], _sign(rng)
    raster = rng.random() < 0.5
    for _ in range(int(rng.integers(1, 4))):
        l, _, _, a = points[-1]
        dz = rng.uniform(-0.015, 0.015) if raster else 0.0
        turn = rng.uniform(-0.3, 0.3) if rng.random() < 1 / 3 else 0.0
        points.append(
            [
                l + direction * rng.uniform(0.04, 0.12),
                z0 + dz,
                h0 + rng.uniform(-0.005, 0.005),
                a + turn,
            ]
        )
    waypoints = [[_r(x) for x in p] for p in points]
    length = float(ToolPath.segment_lengths(np.array([list(tool), *waypoints])).sum())
    speed = max(float(rng.uniform(0.05, 0.12)), length / (MAX_STEPS * dt))
    speed = math.ceil(speed * 1e4) / 1e4
    return {"dt": dt, "path": {"waypoints": waypoints, "speed": speed, "gain": 5.0}}


def tool_track(motion: Table, tool: NDArray[np.float64]) -> NDArray[np.float64]:
    """``[l, z]`` of the commanded tool motion (m): the start, then the end of each JOG
    segment, or each waypoint of a path."""
    points = [np.asarray(tool[:2], dtype=float)]
    if "path" in motion:
        points += [np.asarray(w[:2], dtype=float) for w in motion["path"]["waypoints"]]
    for segment in motion.get("jog", ()):
        points.append(points[-1] + np.asarray(segment["velocity"][:2]) * segment["duration"])
    return np.array(points)
