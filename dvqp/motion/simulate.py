"""Offline integration of DV velocity commands (JOG) with any resolver.

``simulate`` integrates ``q_{k+1} = q_k + dt·Q̇_k`` (explicit Euler, as the paper's JOG), where
``Q̇_k`` is the resolver's answer to the command ``ẋ_k``, optionally with position feedback
toward a DV reference: ``ẋ = ẋ_d + K·(x_d − x)`` with l and α differences wrapped.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.compiled.engine import compile_step
from dvqp.compiled.run import run_compiled
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.motion.advance import MAX_HALVINGS
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.run import Run, dv_error, run_reference
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.step import Resolver

ENGINES = ("auto", "compiled", "reference")
"""How :func:`simulate` steps: see its ``engine`` parameter."""

COMPILE_NOTICE_SECONDS = 1.0
"""s: compiling the step for longer than this is announced through ``notice``."""
COMPILE_NOTICE = "compiling the step (first run; cached after)"

__all__ = ["COMPILE_NOTICE", "ENGINES", "dv_error", "simulate"]


@contextlib.contextmanager
def _noticed(notice: Callable[[str], None] | None) -> Iterator[None]:
    """Call ``notice`` if the block still runs after :data:`COMPILE_NOTICE_SECONDS`."""
    if notice is None:
        yield
        return
    timer = threading.Timer(COMPILE_NOTICE_SECONDS, notice, (COMPILE_NOTICE,))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


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
    engine: str = "auto",
    notice: Callable[[str], None] | None = None,
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
    engine
        ``"auto"``: the compiled step (:mod:`dvqp.compiled`) when every part of the run has a
        kernel, else the reference path; ``"compiled"`` (raise if it cannot be compiled) or
        ``"reference"`` (Pinocchio and NumPy, the path the compiled one is tested against).
    notice
        Called with one line (e.g. for a progress bar) if compiling the step takes longer than
        :data:`COMPILE_NOTICE_SECONDS`: the first run of a composition of tasks, terms, limits
        and shapes compiles it; later runs load it from the cache.

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
    if engine not in ENGINES:
        raise ParameterError("engine", f"must be one of {', '.join(ENGINES)}, got {engine!r}")
    q_start = robot.check_q(q0, "q0")
    KinematicState.compute(robot, q_start, radius)  # a singular start raises here
    resolver.reset()
    for limit in resolver.spec.limits:  # limits that remember motion start at rest
        reset = getattr(limit, "reset", None)
        if reset is not None:
            reset()
    record = TrajectoryRecorder(cmd.shape[0], robot.n, robot.n_points, obstacles)
    run = Run(robot, radius, resolver, q_start, cmd, ref, gain, dt, check, max_halvings, record,
              progress)  # fmt: skip
    compiled = None
    if engine != "reference":
        with _noticed(notice):
            compiled = compile_step(robot, radius, resolver, obstacles, check, record.arrays)
    if compiled is None and engine == "compiled":
        raise ParameterError("engine", "a part of this run has no compiled kernel")
    if compiled is None:
        run_reference(run)
    else:
        run_compiled(compiled, run)
    return record.trajectory(dt, radius, getattr(resolver, "name", type(resolver).__name__))
