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

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import wrap_period
from dvqp.motion.deviation import path_deviation

Array = NDArray[np.float64]

MAX_SLOWDOWN = 4.0
"""A time-scaled run takes at most this many times its nominal steps; a path not finished by
then is reported as not reached (:func:`dvqp.run.planning.check_run`)."""

__all__ = ["MAX_SLOWDOWN", "TIMINGS", "Schedule", "dv_error", "path_deviation"]

TIMINGS = ("fixed", "scaled")
"""How a path's progress is timed: the nominal schedule, or slowed where the limits bind."""


def dv_error(reference: Array, actual: Array, radius: float) -> Array:
    """``x_d − x`` of DV coordinates (…, 4) with l wrapped modulo 2πR and α modulo 2π."""
    e = np.subtract(reference, actual, dtype=np.float64)
    # l and α (components 0 and 3) in one call: periods 2πR and 2π (wrap, wrap_angle)
    e[..., ::3] = wrap_period(e[..., ::3], np.array([2.0 * math.pi * radius, 2.0 * math.pi]))
    return e


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

    def done(self, u: float) -> bool:
        """The nominal schedule has run to its end at progress ``u``."""
        return u >= self.n - 1e-9

    def position(self, u: float) -> Array:
        """``x_d(u)``, shape (4,): the reference at progress ``u`` (time-scaled runs)."""
        nodes = self.nodes
        assert nodes is not None
        i = min(int(u), self.n - 1)
        return nodes[i] + (u - i) * (nodes[i + 1] - nodes[i])

    def command(self, u: float, tool: Array) -> tuple[Array, Array | None, float]:
        """The tool command at progress ``u`` with the tool at ``tool`` (4,): the command (4,),
        its feed-forward for :meth:`dvqp.step.Stepper.pace` (None: fixed timing) and the
        progress the step makes at full rate (1, less at a time-scaled run's last step)."""
        if not self.scaled:
            k = int(u)
            xdot = self.commands[k]
            if self.feedback:
                xdot = xdot + self.gain * dv_error(self.reference[k], tool, self.radius)  # type: ignore[index]
            return xdot, None, 1.0
        span = min(1.0, self.n - u)
        here = self.position(u)
        feedforward = (self.position(u + span) - here) / self.dt
        return feedforward + self.gain * dv_error(here, tool, self.radius), feedforward, span
