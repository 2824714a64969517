"""Offline integration of DV velocity commands (JOG) with any resolver.

``simulate`` integrates ``q_{k+1} = q_k + dt·Q̇_k`` (explicit Euler, as the paper's JOG), where
``Q̇_k`` is the resolver's answer to the command ``ẋ_k``, optionally with position feedback
toward a DV reference: ``ẋ = ẋ_d + K·(x_d − x)`` with l and α differences wrapped.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.errors import ParameterError, ShapeError
from dvqp.objective import Objective
from dvqp.geometry.proximity import proximity
from dvqp.resolution.step import Resolver
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.motion.trajectory import Trajectory

MAX_STEPS = 10_000_000
"""Most steps a planned motion may take."""


@dataclass(frozen=True)
class JogSegment:
    """A constant DV velocity held for a duration.

    Parameters
    ----------
    duration
        s, > 0.
    velocity
        ``[l̇, ż, ḣ, α̇]`` (m/s, m/s, m/s, rad/s), shape (4,).
    """

    duration: float
    velocity: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", _validate.positive("duration", self.duration))
        v = _validate.readonly(_validate.vector("velocity", self.velocity, 4))
        object.__setattr__(self, "velocity", v)


def jog_commands(segments: Sequence[JogSegment], dt: float) -> NDArray[np.float64]:
    """Sample JOG segments every ``dt`` seconds: the commands, shape (N, 4)."""
    step = _validate.positive("dt", dt)
    counts = [max(1, round(s.duration / step)) for s in segments]
    if sum(counts) > MAX_STEPS:
        raise ParameterError("dt", f"{sum(counts)} steps is too many (at most {MAX_STEPS})")
    rows = [np.tile(s.velocity, (c, 1)) for s, c in zip(segments, counts, strict=True)]
    return np.vstack(rows) if rows else np.zeros((0, 4))


def dv_error(
    reference: NDArray[np.float64], actual: NDArray[np.float64], radius: float
) -> NDArray[np.float64]:
    """``x_d − x`` of DV coordinates (…, 4) with l wrapped modulo 2πR and α modulo 2π."""
    e = np.asarray(reference, dtype=float) - np.asarray(actual, dtype=float)
    e[..., 0] = wrap(e[..., 0], radius)
    e[..., 3] = wrap_angle(e[..., 3])
    return e


def min_clearance(state: KinematicState, objective: Objective) -> float:
    """Smallest signed clearance (m) of any body point or link to the objective's obstacles.

    Negative inside an obstacle; ``inf`` with no obstacles.
    """
    return proximity(state, objective.obstacles).min_clearance()  # type: ignore[arg-type]


def simulate(
    robot: Robot,
    pipe_radius: float,
    objective: Objective,
    resolver: Resolver,
    q0: ArrayLike,
    commands: ArrayLike,
    dt: float,
    *,
    reference: ArrayLike | None = None,
    feedback_gain: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the commands from ``q0`` and return the trajectory.

    Parameters
    ----------
    robot, pipe_radius, objective, resolver
        What to simulate (pipe radius in m).
    q0
        Start configuration, rad, shape (n,).
    commands
        Feed-forward tool DV velocities, shape (N, 4).
    dt
        Step, s, > 0.
    reference
        Optional DV positions ``x_d(t_k)``, shape (N, 4), for position feedback.
    feedback_gain
        ``K`` (1/s) of the feedback, >= 0.
    progress
        Called as ``progress(k, N)`` after each step.

    Notes
    -----
    A step whose resolver reports failure holds the arm still (``Q̇ = 0``) for that step and
    is recorded as failed in the trajectory's diagnostics.
    """
    step = _validate.positive("dt", dt)
    gain = _validate.positive("feedback_gain", feedback_gain, strict=False)
    radius = _validate.positive("pipe_radius", pipe_radius)
    cmd = np.asarray(commands, dtype=float)
    if cmd.ndim != 2 or cmd.shape[1] != 4:
        raise ShapeError("commands", (-1, 4), cmd.shape)
    if not np.all(np.isfinite(cmd)):
        raise ParameterError("commands", "must be finite")
    n_steps = cmd.shape[0]
    ref = None
    if reference is not None:
        ref = np.asarray(reference, dtype=float)
        if ref.shape != cmd.shape:
            raise ShapeError("reference", cmd.shape, ref.shape)
    q = robot.check_q(q0, "q0").copy()
    resolver.reset()
    n, k = robot.n, robot.n_points
    qs = np.empty((n_steps + 1, n))
    qdots = np.zeros((n_steps, n))
    tool = np.empty((n_steps + 1, 4))
    points = np.empty((n_steps + 1, k, 3))
    w = np.empty(n_steps + 1)
    clearance = np.empty(n_steps + 1)
    times = np.zeros(n_steps)
    step_times = np.zeros(n_steps)
    errors = np.zeros(n_steps)
    iterations = np.full(n_steps, -1, dtype=np.int64)
    ok = np.zeros(n_steps, dtype=bool)
    status: list[str] = []
    for i in range(n_steps + 1):
        started = time.perf_counter()
        state = KinematicState.compute(robot, q, radius)
        term = objective.evaluate(state)
        if i < n_steps:
            xdot = cmd[i]
            if ref is not None and gain > 0.0:
                xdot = xdot + gain * dv_error(ref[i], state.tool, radius)
            result = resolver.resolve(state, objective.gain * term.gradient, xdot, step)
            step_times[i] = time.perf_counter() - started
        qs[i], tool[i], points[i] = q, state.tool, state.points
        w[i] = term.value
        clearance[i] = min_clearance(state, objective)
        if i == n_steps:
            break
        times[i], errors[i], ok[i] = result.solve_time, result.task_error, result.success
        iterations[i] = -1 if result.iterations is None else result.iterations
        status.append(result.status)
        if result.success:
            qdots[i] = result.qdot
            q = q + step * result.qdot
        if progress is not None:
            progress(i + 1, n_steps)
    return Trajectory.from_samples(
        dt=step,
        q=qs,
        qdot=qdots,
        tool=tool,
        points=points,
        pipe_radius=radius,
        w=w,
        min_clearance=clearance,
        solve_time=times,
        step_time=step_times,
        task_error=errors,
        iterations=iterations,
        success=ok,
        status=status,
        backend=getattr(resolver, "name", type(resolver).__name__),
    )
