"""Offline integration of DV velocity commands (JOG) with any resolver.

``simulate`` integrates ``q_{k+1} = q_k + dt·Q̇_k`` (explicit Euler, as the paper's JOG), where
``Q̇_k`` is the resolver's answer to the command ``ẋ_k``, optionally with position feedback
toward a DV reference: ``ẋ = ẋ_d + K·(x_d − x)`` with l and α differences wrapped. Every step
is the compiled step (:class:`~dvqp.step.Stepper`), verified exactly
(:func:`~dvqp.step.advance`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
import time
from collections.abc import Callable, Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.robot import Robot
from dvqp.motion.follow import Follower
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.schedule import Schedule, dv_error
from dvqp.motion.stop import brake, room
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.step import Resolver
from dvqp.step import MAX_HALVINGS, Stepper, advance
from solvers import Problem, Solution
from solvers.jit import compiled_count

Array = NDArray[np.float64]

COMPILE_NOTICE_SECONDS = 1.0
"""s: compiling the step for longer than this is announced through ``notice``."""
COMPILE_NOTICE = "compiling: first run only, ~30 s"

#: ``progress(k, N)``: k of the run's N nominal steps done.
Progress = Callable[[int, int], None]
#: ``(step, kind, problem, solution)`` of a backend call (:func:`simulate`'s ``watch``).
StepWatcher = Callable[[int, str, Problem, Solution], None]

__all__ = ["COMPILE_NOTICE", "dv_error", "simulate"]


@contextlib.contextmanager
def _noticed(notice: Callable[[str], None] | None) -> Iterator[None]:
    """Call ``notice`` if the block still runs after :data:`COMPILE_NOTICE_SECONDS`, and once
    more when it ends, with how long it took."""
    if notice is None:
        yield
        return
    started = time.perf_counter()
    timer = threading.Timer(COMPILE_NOTICE_SECONDS, notice, (COMPILE_NOTICE,))
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
        if timer.finished.is_set() and time.perf_counter() - started > COMPILE_NOTICE_SECONDS:
            notice(f"compiled in {time.perf_counter() - started:.0f} s, cached")


def _check_commands(commands: ArrayLike, reference: ArrayLike | None) -> tuple[Array, Array | None]:
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
    notice: Callable[[str], None] | None = None,
    stop: bool = True,
    watch: StepWatcher | None = None,
    time_scaling: bool = False,
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
        steps that break one (:func:`dvqp.step.advance`). Default: if the resolver holds
        limits (the QP); the baseline's excess is measured and recorded only.
    max_halvings
        Most times a step is halved to keep the limits.
    progress
        Called as ``progress(k, N)`` after each step.
    notice
        Called with one line (e.g. for a progress bar) if compiling the step takes longer than
        :data:`COMPILE_NOTICE_SECONDS` (the first run after installing dvqp compiles it; later
        runs load it from numba's cache), and once more when compiling is done.
    stop
        After the last command, brake until every joint has stopped (:mod:`dvqp.motion.stop`):
        the run ends at rest, ``qdot[-1] == 0`` exactly, and ``brake_start`` is the first
        braking step. False: end after the last command (e.g. to chain runs).
    watch
        A QP run's every backend call (not the one that compiles the step first) is shown to it
        as ``watch(step, kind, problem, solution)``: ``step`` the recorded step it belongs to
        (the braking steps continue the count), the rest as a
        :data:`~dvqp.resolution.qp.Watcher` gets them.
    time_scaling
        Follow ``reference`` time-scaled (:mod:`dvqp.motion.schedule`): where the limits
        bind, a QP step slows along the path (status ``"slowed"``) rather than leave it, and
        the run takes as many steps as it needs (at most
        :data:`~dvqp.motion.schedule.MAX_SLOWDOWN` times ``N``). The trajectory's
        ``path_time`` holds the nominal time reached at each sample.

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
    check = resolver.holds_limits if verify is None else verify
    q_start = robot.check_q(q0, "q0")
    reserved = room(robot, resolver, dt) if stop else 0  # the stop's samples, in advance
    levels = resolver.spec.level_names
    record = TrajectoryRecorder(
        cmd.shape[0] + reserved, robot.n, robot.n_points, robot.has_rail, len(levels)
    )
    schedule = Schedule(cmd, ref, gain, dt, radius, time_scaling)
    with _noticed(notice):
        compiled = compiled_count()
        stepper = Stepper(robot, radius, resolver, q_start, dt, obstacles, record.arrays)
        follower = Follower(stepper, record, schedule, check)
        _compiled(stepper, follower, q_start, compiled)
    if watch is not None and stepper.solver is not None:
        stepper.solver.watchers.append(lambda kind, p, s: watch(record.steps, kind, p, s))
    n, path_time = _follow(stepper, record, schedule, follower, check, max_halvings, progress)
    steps = brake(stepper, record, n, dt, verify=check, max_halvings=max_halvings) if stop else 0
    solver = stepper.solver
    refused = {} if solver is None else dict(solver.refusals)
    accuracy = {} if solver is None else solver.accuracy.to_dict()
    braked = n if stop else -1
    traj = record.trajectory(
        dt,
        radius,
        resolver.name,
        n + steps,
        braked,
        stepper.start_broken(),
        refused,
        accuracy,
        levels,
    )
    held = np.full(steps, path_time[-1])
    return dataclasses.replace(traj, path_time=np.concatenate([path_time, held]))


def _compiled(stepper: Stepper, follower: Follower, q0: Array, compiled: int) -> None:
    """Compile (or load) every call of the run's step and loop (a step of its first command
    resolved, none of the loop; the loop as :data:`dvqp.motion.follow.COMPILE` says:
    ``compiled``, the kernels compiled in the process before the run's step was made), and the
    calls a step taken in Python makes (the schedule's command, the step resolved and moved in
    one call, the relaxed problem's copy), so that no step's time holds a compile; then start
    afresh from ``q0``, the relaxed and least-violation problems' backends set up on that
    step's problems (:meth:`~dvqp.resolution.qp.QPSolver.set_up_fallbacks`: no step's time
    holds a set-up)."""
    stepper.start(q0)
    schedule = follower.schedule
    if schedule.n:
        command, dt = schedule.commands[0], schedule.dt
        stepper.resolve(command, dt)
        follower.compile(warm=compiled_count() == compiled)
        schedule.command(0.0, stepper.state.tool)  # and the calls of a step taken in Python
        stepper.record_at[0] = -1
        stepper.resolve_and_move(command, dt)
        if stepper.solver is not None:
            stepper.solver.load_relaxed_problem()
        stepper.record_at[0] = 0
        stepper.start(q0)
        if stepper.solver is not None:  # on that step's relaxed problem (start resets it)
            stepper.solver.set_up_fallbacks()


def _follow(
    stepper: Stepper,
    record: TrajectoryRecorder,
    schedule: Schedule,
    follower: Follower,
    check: bool,
    max_halvings: int,
    progress: Progress | None,
) -> tuple[int, Array]:
    """Run the schedule's commands; the steps taken and the nominal time (s) at each sample.

    The common steps run in the compiled loop (:mod:`dvqp.motion.follow`), the others here:
    the step it hands over (made, not taken), or each step when it cannot run (parts of
    your own, watched backend calls)."""
    u, k, dt = 0.0, 0, schedule.dt
    started = time.perf_counter()
    while not schedule.done(u) and k < schedule.budget:
        if k >= record.arrays["qdot"].shape[0]:  # a slowed run outgrew its room
            record.extend(schedule.n)
            stepper.record_into(record.arrays)
        first = k
        k, u, started, made = follower.run(k, u, started)
        if progress is not None:
            for j in range(first + 1, k + 1):
                progress(_done(schedule, follower.progress[j], j), schedule.n)
        if made is None:
            if k > first:
                continue  # stopped before step k: the schedule's end, its budget, or no room
            xdot, feedforward, span = schedule.command(u, stepper.state.tool)
            if schedule.scaled:  # fixed timing: the feed-forward stays 0, nothing to write
                stepper.pace(feedforward)
        else:  # step k, made by the loop from its command
            xdot, span = stepper.arrays.command.copy(), schedule.span(u)
        moved = advance(
            stepper, xdot, dt, verify=check, max_halvings=max_halvings, record=k + 1, made=made
        )
        now = time.perf_counter()
        record.step(k, moved, now - started)
        started = now
        u += (moved.step.rate if schedule.scaled else 1.0) * span
        k += 1
        follower.progress[k] = u
        if progress is not None:
            progress(_done(schedule, u, k), schedule.n)
    if schedule.scaled:
        stepper.pace(None)  # the stop, and whatever runs next, at fixed timing
    return k, np.minimum(follower.progress[: k + 1], schedule.n) * dt


def _done(schedule: Schedule, u: float, k: int) -> int:
    """The nominal steps done after step ``k`` at progress ``u`` (for ``progress``)."""
    return min(round(float(u)), schedule.n) if schedule.scaled else k
