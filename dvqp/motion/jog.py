"""JOG commands: constant developed-view velocities held for a while, as the operator's keys."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError

MAX_STEPS = 10_000_000
"""Most steps a planned motion may take."""
DEFAULT_GAIN_STEP = 0.5
"""The share of its reference error a JOG of a scene with tasks at more than one priority
closes each step by default: its feedback ``ẋ = ẋ_c + K (x_ref − x)`` (the reference the start
plus the integrated commands, as a path's) has ``K = 0.5 / dt`` (100/s at dt = 5 ms; at most
1000/s). Each step meets the command in velocity; the feedback removes what the steps'
second-order error adds up to, to about twice one step's. 0 is the paper's JOG (velocities
only, the default of a scene of one level): the integrated probe then drifts by those errors."""
MAX_GAIN = 1000.0
"""1/s: the largest feedback gain a scene takes."""


def default_gain(dt: float) -> float:
    """``K`` of a JOG with levels by default, 1/s: :data:`DEFAULT_GAIN_STEP` ``/ dt``, at most
    :data:`MAX_GAIN`."""
    return min(DEFAULT_GAIN_STEP / dt, MAX_GAIN)


DEFAULT_RAMP = 0.2
"""s: a JOG's velocity changes (its start, its end, between segments) are spread over this."""


@dataclass(frozen=True)
class JogSegment:
    """A constant DV velocity ``[l̇, ż, ḣ, α̇]`` (m/s, m/s, m/s, rad/s; shape (4,)) held for
    ``duration`` s (> 0)."""

    duration: float
    velocity: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", _validate.positive("duration", self.duration))
        v = _validate.readonly(_validate.vector("velocity", self.velocity, 4))
        object.__setattr__(self, "velocity", v)


def jog_step_count(segments: Sequence[JogSegment], dt: float) -> int:
    """How many steps of ``dt`` the segments take (each at least one)."""
    return sum(max(1, round(s.duration / dt)) for s in segments)


def jog_commands(
    segments: Sequence[JogSegment], dt: float, ramp: float = 0.0
) -> NDArray[np.float64]:
    """Sample JOG segments every ``dt`` seconds: the commands, shape (N, 4).

    With ``ramp > 0`` (s) the piecewise-constant commands, from rest and back to rest, are
    averaged over a window of ``W = round(ramp/dt)`` steps: every change of velocity becomes
    a linear ramp lasting ``W`` steps, so the commanded velocity is continuous, the motion
    starts and ends at rest, and the total displacement is exactly that of the segments. The
    run is ``W − 1`` steps longer.
    """
    dt = _validate.positive("dt", dt)
    counts = [max(1, round(s.duration / dt)) for s in segments]
    if sum(counts) > MAX_STEPS:
        raise ParameterError("dt", f"{sum(counts)} steps is too many (at most {MAX_STEPS})")
    commands = np.repeat(np.reshape([s.velocity for s in segments], (-1, 4)), counts, axis=0)
    window = round(_validate.positive("ramp", ramp, strict=False) / dt)
    if window <= 1 or commands.shape[0] == 0:
        return commands
    pad = np.zeros((window - 1, commands.shape[1]))
    return box_average(np.vstack([pad, commands, pad]), window)


def box_average(rows: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    """Means of every ``window`` consecutive rows of ``rows`` (m, c): shape (m − window + 1, c)."""
    total = np.cumsum(np.vstack([np.zeros((1, rows.shape[1])), rows]), axis=0)
    return (total[window:] - total[:-window]) / window
