"""Where a run's commands stand at each step: on their own clock, or on a path's progress.

A run of ``N`` commands is driven by its progress ``u`` (in steps of the nominal schedule,
``0 ≤ u ≤ N``). With fixed timing (the paper's), step ``k`` takes command ``k`` and ``u = k``.
Time-scaled path following (:attr:`Schedule.scaled`) lets the step's QP choose how much of the
nominal progress it makes (:meth:`dvqp.step.Stepper.pace`): a step from ``u`` commands the
nominal motion from ``x_d(u)`` to ``x_d(u + 1)`` (the feed-forward, which the QP may scale by
``σ ∈ [0, 1]``) plus the feedback ``K (x_d(u) − x)``, and advances ``u`` by ``σ``; the path's
reference ``x_d`` is interpolated linearly between its samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import wrap_period
from dvqp.motion.deviation import path_deviation
from dvqp.workspace import as_struct
from solvers.jit import njit

Array = NDArray[np.float64]

MAX_SLOWDOWN = 4.0
"""A time-scaled run takes at most this many times its nominal steps; a path not finished by
then is reported as not reached (:func:`dvqp.run.planning.check_run`)."""

__all__ = [
    "MAX_SLOWDOWN",
    "TIMINGS",
    "Schedule",
    "ScheduleArrays",
    "command_into",
    "dv_error",
    "path_deviation",
]

TIMINGS = ("fixed", "scaled")
"""How a path's progress is timed: the nominal schedule, or slowed where the limits bind."""


def dv_error(reference: Array, actual: Array, radius: float) -> Array:
    """``x_d − x`` of DV coordinates (…, 4) with l wrapped modulo 2πR and α modulo 2π."""
    e = np.subtract(reference, actual, dtype=np.float64)
    # l and α (components 0 and 3) in one call: periods 2πR and 2π (wrap, wrap_angle)
    e[..., ::3] = wrap_period(e[..., ::3], np.array([2.0 * math.pi * radius, 2.0 * math.pi]))
    return e


@dataclass(frozen=True)
class ScheduleArrays:
    """A :class:`Schedule` as compiled code reads it (:func:`command_into`): ``commands``
    (N, 4), ``reference`` (N, 4; (0, 4) without feedback), the time-scaled path's ``nodes``
    (N + 1, 4; (0, 4) at fixed timing), the gain ``K`` (1/s), ``dt`` (s), the pipe's
    ``radius`` (m), ``n = N`` and the two flags."""

    commands: Array
    reference: Array
    nodes: Array
    gain: float
    dt: float
    radius: float
    n: int
    feedback: bool
    scaled: bool


class Schedule:
    """The commands of a run and its progress.

    Parameters
    ----------
    commands
        Feed-forward tool DV velocities of the nominal schedule, shape (N, 4).
    reference
        ``x_d`` at the start of each nominal step, shape (N, 4), or None (no feedback).
    gain
        Feedback gain ``K``, 1/s (0: no feedback).
    dt, radius
        Step (s) and pipe radius (m).
    scaled
        Time-scaled following (needs ``reference``; ``commands[k]·dt`` must be
        ``reference[k+1] − reference[k]``, as a path's are).
    """

    def __init__(
        self,
        commands: Array,
        reference: Array | None,
        gain: float,
        dt: float,
        radius: float,
        scaled: bool = False,
    ) -> None:
        if scaled and reference is None:
            raise ParameterError("timing", "time scaling follows a path: it needs its reference")
        self.commands, self.reference = commands, reference
        self.feedback = reference is not None and gain > 0.0
        self.gain, self.dt, self.radius, self.scaled = gain, dt, radius, scaled
        self.n = commands.shape[0]
        self.budget = math.ceil(MAX_SLOWDOWN * self.n) if scaled else self.n
        """The most steps the run takes."""
        self.nodes = np.vstack([reference, reference[-1:] + dt * commands[-1:]]) if scaled else None
        none = np.zeros((0, 4))
        self.arrays = ScheduleArrays(
            np.ascontiguousarray(commands, dtype=np.float64),
            none if reference is None else np.ascontiguousarray(reference, dtype=np.float64),
            none if self.nodes is None else np.ascontiguousarray(self.nodes),
            float(gain),
            float(dt),
            float(radius),
            int(self.n),
            bool(self.feedback),
            bool(scaled),
        )
        """The schedule for compiled code (:func:`command_into`)."""
        self.struct = as_struct(self.arrays)

    def done(self, u: float) -> bool:
        """The nominal schedule has run to its end at progress ``u``."""
        return u >= self.n - 1e-9

    def span(self, u: float) -> float:
        """The progress a step from ``u`` makes at full rate: 1, less at a time-scaled run's
        last step."""
        return min(1.0, self.n - u) if self.scaled else 1.0

    def command(self, u: float, tool: Array) -> tuple[Array, Array | None, float]:
        """The tool command at progress ``u`` with the tool at ``tool`` (4,): the command (4,),
        its feed-forward for :meth:`dvqp.step.Stepper.pace` (None: fixed timing) and the
        progress the step makes at full rate (:meth:`span`)."""
        xdot, feedforward = np.empty(4), np.empty(4)
        span = command_into(self.struct, u, np.array(tool, dtype=np.float64), xdot, feedforward)
        return xdot, feedforward if self.scaled else None, span


@njit(inline="always")
def _position(a, u, c):  # type: ignore[no-untyped-def]
    """Component ``c`` of ``x_d(u)``: the path's nodes interpolated linearly."""
    i = int(u)
    if i > a.n - 1:
        i = a.n - 1
    return a.nodes[i, c] + (u - i) * (a.nodes[i + 1, c] - a.nodes[i, c])


@njit(inline="always")
def _wrapped(a, e, c):  # type: ignore[no-untyped-def]
    """Component ``c`` of a DV difference ``e``, l wrapped modulo 2πR and α modulo 2π."""
    if c == 0:
        return wrap_period(e, 2.0 * math.pi * a.radius)
    if c == 3:
        return wrap_period(e, 2.0 * math.pi)
    return e


@njit(separate=True, python=True)  # a run's compiled loop calls it, and Schedule.command
def command_into(a, u, tool, xdot, feedforward):  # type: ignore[no-untyped-def]
    """The tool command of the schedule ``a`` (:class:`ScheduleArrays`) at progress ``u`` with
    the tool at ``tool`` (4,), written into ``xdot`` (4,), and at a time-scaled run its
    feed-forward into ``feedforward`` (4,; untouched at fixed timing); returns the progress
    the step makes at full rate.

    Fixed timing: command ``k = int(u)``, plus ``K (x_d[k] − x)`` with feedback. Time-scaled:
    the nominal motion from ``x_d(u)`` to ``x_d(u + span)`` over ``dt``, plus
    ``K (x_d(u) − x)``. ``x_d − x`` wraps l modulo 2πR and α modulo 2π (:func:`dv_error`).
    """
    if not a.scaled:
        k = int(u)
        for c in range(4):
            xdot[c] = a.commands[k, c]
            if a.feedback:
                xdot[c] = xdot[c] + a.gain * _wrapped(a, a.reference[k, c] - tool[c], c)
        return 1.0
    span = a.n - u if a.n - u < 1.0 else 1.0  # min(1, n − u)
    for c in range(4):
        here = _position(a, u, c)
        feedforward[c] = (_position(a, u + span, c) - here) / a.dt
        xdot[c] = feedforward[c] + a.gain * _wrapped(a, here - tool[c], c)
    return span
