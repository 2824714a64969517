"""Offline integration of DV velocity commands (JOG) with any resolver.

``simulate`` integrates ``q_{k+1} = q_k + dt·Q̇_k`` (explicit Euler, as the paper's JOG), where
``Q̇_k`` is the resolver's answer to the command ``ẋ_k``, optionally with position feedback
toward a DV reference: ``ẋ = ẋ_d + K·(x_d − x)`` with l and α differences wrapped.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import NO_EXCESS
from dvqp.motion.advance import MAX_HALVINGS, advance
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.step import Resolver


def dv_error(
    reference: NDArray[np.float64], actual: NDArray[np.float64], radius: float
) -> NDArray[np.float64]:
    """``x_d − x`` of DV coordinates (…, 4) with l wrapped modulo 2πR and α modulo 2π."""
    e = np.asarray(reference, dtype=float) - np.asarray(actual, dtype=float)
    e[..., 0] = wrap(e[..., 0], radius)
    e[..., 3] = wrap_angle(e[..., 3])
    return e


def _check_commands(
    commands: ArrayLike, reference: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
    cmd = np.asarray(commands, dtype=float)
    if cmd.ndim != 2 or cmd.shape[1] != 4:
        raise ShapeError("commands", (-1, 4), cmd.shape)
    if not np.all(np.isfinite(cmd)):
        raise ParameterError("commands", "must be finite")
    if reference is None:
        return cmd, None
    ref = np.asarray(reference, dtype=float)
    if ref.shape != cmd.shape:
        raise ShapeError("reference", cmd.shape, ref.shape)
    return cmd, ref


def simulate(
    robot: Robot,
    pipe_radius: float,
    resolver: Resolver,
    q0: ArrayLike,
    commands: ArrayLike,
    dt: float,
    *,
    obstacles: ObstacleSet | None = None,
    reference: ArrayLike | None = None,
    feedback_gain: float = 0.0,
    verify: bool | None = None,
    max_halvings: int = MAX_HALVINGS,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Run the commands from ``q0`` and return the trajectory.

    Parameters
    ----------
    robot, pipe_radius, resolver
        What to simulate (pipe radius in m); the objective is the resolver's.
    q0
        Start configuration, rad, shape (n,).
    commands
        Feed-forward tool DV velocities, shape (N, 4).
    dt
        Step, s, > 0.
    obstacles
        The obstacles whose clearance the trajectory records (none: ``inf``).
    reference
        Optional DV positions ``x_d(t_k)``, shape (N, 4), for position feedback.
    feedback_gain
        ``K`` (1/s) of the feedback, >= 0.
    verify
        Check every limit of the resolver's spec exactly after each step, splitting or failing
        steps that break one (:func:`dvqp.motion.advance.advance`). Default: if the resolver
        holds limits (the QP); the baseline's excess is measured and recorded only.
    max_halvings
        Most times a step is halved to keep the limits.
    progress
        Called as ``progress(k, N)`` after each step.

    Notes
    -----
    A step whose resolver reports failure, or that still breaks a limit after
    ``max_halvings`` halvings, holds the arm still (``Q̇ = 0``) for that step and is recorded
    as failed, its status naming the reason.
    """
    dt = _validate.positive("dt", dt)
    gain = _validate.positive("feedback_gain", feedback_gain, strict=False)
    radius = _validate.positive("pipe_radius", pipe_radius)
    cmd, ref = _check_commands(commands, reference)
    obstacles = ObstacleSet() if obstacles is None else obstacles
    check = getattr(resolver, "holds_limits", True) if verify is None else verify
    objective = resolver.spec.objective
    state = start = KinematicState.compute(robot, robot.check_q(q0, "q0"), radius)
    resolver.reset()
    for limit in resolver.spec.limits:  # limits that remember motion start at rest
        reset = getattr(limit, "reset", None)
        if reset is not None:
            reset()
    n_steps = cmd.shape[0]
    record = TrajectoryRecorder(n_steps, robot.n, robot.n_points, obstacles)
    started = time.perf_counter()
    excess = NO_EXCESS
    for i in range(n_steps + 1):
        record.sample(i, state, objective.evaluate(state).value, excess)
        if i == n_steps:
            break
        xdot = cmd[i]
        if ref is not None and gain > 0.0:
            xdot = xdot + gain * dv_error(ref[i], state.tool, radius)
        moved = advance(
            robot, radius, resolver, state, xdot, dt, start=start, verify=check,
            max_halvings=max_halvings,
        )  # fmt: skip
        now = time.perf_counter()
        record.step(i, moved, now - started)
        started, state = now, moved.state
        if moved.step.success:
            excess = moved.excess
        if progress is not None:
            progress(i + 1, n_steps)
    return record.trajectory(dt, radius, getattr(resolver, "name", type(resolver).__name__))
