"""The inputs of one simulated run, and its reference (uncompiled) loop."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import NO_EXCESS
from dvqp.motion.advance import advance
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.resolution.step import Resolver


def dv_error(
    reference: NDArray[np.float64], actual: NDArray[np.float64], radius: float
) -> NDArray[np.float64]:
    """``x_d − x`` of DV coordinates (…, 4) with l wrapped modulo 2πR and α modulo 2π."""
    e = np.asarray(reference, dtype=float) - np.asarray(actual, dtype=float)
    e[..., 0] = wrap(e[..., 0], radius)
    e[..., 3] = wrap_angle(e[..., 3])
    return e


@dataclass(frozen=True)
class Run:
    """What :func:`dvqp.motion.simulate.simulate` runs, checked already.

    Attributes
    ----------
    robot, radius, resolver
        The arm, the pipe radius (m) and the resolver.
    q0 : ndarray, shape (n,)
        Start, rad.
    commands : ndarray, shape (N, 4)
        Feed-forward tool DV velocities.
    reference : ndarray, shape (N, 4), or None
        DV positions for feedback.
    gain : float
        Feedback gain, 1/s.
    dt : float
        Step, s.
    verify : bool
        Split and fail steps that break a limit.
    max_halvings : int
        Most halvings of a step.
    record : TrajectoryRecorder
        Where the samples and steps go.
    progress : callable or None
        ``progress(k, N)`` after each step.
    """

    robot: Robot
    radius: float
    resolver: Resolver
    q0: NDArray[np.float64]
    commands: NDArray[np.float64]
    reference: NDArray[np.float64] | None
    gain: float
    dt: float
    verify: bool
    max_halvings: int
    record: TrajectoryRecorder
    progress: Callable[[int, int], None] | None

    def command(self, i: int, tool: NDArray[np.float64]) -> NDArray[np.float64]:
        """Step i's command at the tool's DV position ``tool`` (with feedback, if any)."""
        xdot = self.commands[i]
        if self.reference is not None and self.gain > 0.0:
            xdot = xdot + self.gain * dv_error(self.reference[i], tool, self.radius)
        return xdot

    def advance(self, state: KinematicState, xdot: NDArray[np.float64], start: KinematicState):  # type: ignore[no-untyped-def]
        """The reference step from ``state`` (:func:`dvqp.motion.advance.advance`)."""
        return advance(
            self.robot, self.radius, self.resolver, state, xdot, self.dt, start=start,
            verify=self.verify, max_halvings=self.max_halvings,
        )  # fmt: skip


def run_reference(run: Run) -> None:
    """Simulate ``run`` step by step on the reference path (Pinocchio and NumPy)."""
    objective, record = run.resolver.spec.objective, run.record
    state = start = KinematicState.compute(run.robot, run.q0, run.radius)
    n_steps = run.commands.shape[0]
    started = time.perf_counter()
    excess = NO_EXCESS
    for i in range(n_steps + 1):
        record.sample(i, state, objective.evaluate(state).value, excess)
        if i == n_steps:
            break
        moved = run.advance(state, run.command(i, state.tool), start)
        now = time.perf_counter()
        record.step(i, moved, now - started)
        started, state = now, moved.state
        if moved.step.success:
            excess = moved.excess
        if run.progress is not None:
            run.progress(i + 1, n_steps)
