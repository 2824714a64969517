"""Offline trajectory generation from a :class:`~dvqp.scenes.Scene`.

:func:`plan` runs a scene's motion with a named resolver (``"pinv"``, the paper's baseline, or
a QP backend) on the scene's step plus any tasks and limits of the caller's. In JOG mode the
tool gets the JOG velocities with position feedback on their integral (the scene's
``[motion] gain``); in path mode it follows the waypoints with position feedback
``ẋ = ẋ_d + K(x_d − x)``, on the nominal schedule or time-scaled (``timing``,
:mod:`dvqp.motion.schedule`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import LimitViolationError, ParameterError, UnreachableTargetError
from dvqp.kinematics.state import KinematicState
from dvqp.limits import Limit, start_broken_lines
from dvqp.motion.jog import box_average, jog_commands
from dvqp.motion.schedule import MAX_SLOWDOWN, TIMINGS, path_deviation
from dvqp.motion.simulate import StepWatcher, dv_error, simulate
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.registry import make_resolver, tier_options
from dvqp.run.levels import level_deviation
from dvqp.run.sample_checks import final_errors, worst_sample_excess
from dvqp.scenes.scene import Scene
from dvqp.tasks import Task


@dataclass(frozen=True)
class Commands:
    """The sampled commands of a scene.

    Attributes
    ----------
    velocity : ndarray, shape (N, 4)
        Feed-forward tool DV velocities ``ẋ_d`` per step (m/s, m/s, m/s, rad/s).
    reference : ndarray, shape (N+1, 4)
        ``x_d(t_k)``, l and α unwrapped: the path, or in JOG mode the start plus the
        integrated commands.
    feedback_gain : float
        ``K``, 1/s: the path's, or in JOG mode the scene's ``[motion] gain`` (0: the paper's
        JOG, velocities only).
    """

    velocity: NDArray[np.float64]
    reference: NDArray[np.float64]
    feedback_gain: float


def scene_commands(scene: Scene) -> Commands:
    """Sample a scene's JOG segments or path every ``scene.dt``."""
    tool0 = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius).tool
    if scene.path is None:
        cmd = jog_commands(scene.jog, scene.dt, scene.ramp)
        ref = tool0 + np.vstack([np.zeros(4), np.cumsum(cmd * scene.dt, axis=0)])
        return Commands(cmd, ref, scene.jog_gain)
    ref = ramped(scene.path.reference(tool0, scene.dt, scene.pipe_radius), scene.ramp, scene.dt)
    return Commands(np.diff(ref, axis=0) / scene.dt, ref, scene.path.gain)


def ramped(reference: NDArray[np.float64], ramp: float, dt: float) -> NDArray[np.float64]:
    """A path reference ``(N+1, 4)`` whose start and stop take ``ramp`` seconds.

    The positions are averaged over ``W = round(ramp/dt)`` samples, the first and last held
    before and after: the velocity rises and falls linearly over ``W`` steps instead of
    jumping, the path and its end are unchanged, and the run is ``W − 1`` steps longer.
    """
    window = round(ramp / dt)
    if window <= 1:
        return reference
    return box_average(np.pad(reference, ((window - 1, window - 1), (0, 0)), mode="edge"), window)


def plan(
    scene: Scene,
    backend: str = "daqp",
    *,
    tasks: Sequence[Task] = (),
    limits: Sequence[Limit] = (),
    progress: Callable[[int, int], None] | None = None,
    notice: Callable[[str], None] | None = None,
    stop: bool = True,
    options: dict[str, Any] | None = None,
    tier: str = "default",
    watch: StepWatcher | None = None,
    timing: str | None = None,
) -> Trajectory:
    """Run a scene with a resolver and return its trajectory, ended at rest.

    The trajectory carries the scene text and ``tracking_error`` (``x_d − x`` per sample,
    l and α wrapped; the braking samples against the motion's end, held). A failed run is
    returned as well; :func:`check_run` says why it failed.

    Parameters
    ----------
    backend
        ``"pinv"`` or a QP backend name (:func:`dvqp.resolution.registry.available_resolvers`).
    tasks, limits
        Tasks and limits added to the scene's own (the baseline ignores limits); a task joins
        the level of its ``priority`` (each level kept as well as the limits and the levels
        above let it, :mod:`dvqp.resolution.levels`). The trajectory records each level's
        residual per step and error per sample (:attr:`Trajectory.level_error`,
        :attr:`~Trajectory.level_deviation`).
    progress
        Called as ``progress(k, N)`` after each step.
    notice
        Called with one line if compiling the step takes long (the first run after
        installing); see :func:`dvqp.motion.simulate.simulate`.
    stop
        Brake after the last command (JOG) or the path's end until every joint has stopped
        (:mod:`dvqp.motion.stop`); False: end with the last command.
    options
        Settings of the QP backend, over the scene's ``[solvers.<backend>]`` ones, over the
        settings ``tier``'s.
    tier
        The QP backend's accuracy settings and the tolerance its answers are checked to
        (:mod:`solvers.tiers`): ``"default"`` (dvqp's own, tight), qpbenchmark's
        ``"high_accuracy"``, ``"mid_accuracy"``, ``"low_accuracy"``, or
        ``"solver_defaults"`` (qpbenchmark's ``default``: the solvers' factory defaults).
    watch
        Shown every backend call of the run (:func:`dvqp.motion.simulate.simulate`).
    timing
        A path's timing, ``"fixed"`` or ``"scaled"`` (slow down along the path where the
        limits bind, rather than leave it); default: the scene's (``fixed`` if it says none).
        The tracking error is then against the path where the run had reached on it.

    Raises
    ------
    BackendError
        Unknown backend, or a setting it does not take.
    ParameterError
        An unknown ``tier`` or ``timing``, or time scaling asked of a JOG scene.
    SingularConfigurationError
        The baseline met a singular task Jacobian.
    """
    settings = backend_settings(scene, backend, options, tier)
    spec = scene.spec().with_extra(tasks, limits)
    resolver = make_resolver(backend, spec, settings)
    c = scene_commands(scene)
    scaled = scene_timing(scene, timing) == "scaled"
    traj = simulate(
        scene.robot,
        scene.pipe_radius,
        resolver,
        scene.q0,
        c.velocity,
        scene.dt,
        obstacles=scene.obstacles,
        reference=c.reference[:-1] if c.feedback_gain > 0 else None,
        feedback_gain=c.feedback_gain,
        progress=progress,
        notice=notice,
        stop=stop,
        watch=watch,
        time_scaling=scaled,
    )
    if scaled:  # the reference where the run had reached on the path
        nodes = np.arange(c.reference.shape[0])
        u = traj.path_time / scene.dt
        reference = np.column_stack([np.interp(u, nodes, col) for col in c.reference.T])
    else:
        held = c.reference[-1:].repeat(traj.t.shape[0] - c.reference.shape[0], axis=0)
        reference = np.vstack([c.reference, held])
    error = dv_error(reference, traj.tool, scene.pipe_radius)
    traj = dataclasses.replace(traj, tracking_error=error, scene_text=scene.text)
    deviation, measured = level_deviation(spec, traj)
    return dataclasses.replace(traj, level_deviation=deviation, level_measured=measured)


def scene_timing(scene: Scene, timing: str | None = None) -> str:
    """The timing a run of ``scene`` follows: ``timing``, else its path's, else ``"fixed"``.

    Raises
    ------
    ParameterError
        An unknown timing, or ``"scaled"`` for a JOG scene (there is no path to slow along).
    """
    chosen = timing or (scene.path.timing if scene.path is not None else "fixed")
    if chosen not in TIMINGS:
        raise ParameterError("timing", f"must be one of {', '.join(TIMINGS)}, got {chosen!r}")
    if chosen == "scaled" and scene.path is None:
        raise ParameterError("timing", f"{scene.source}: a JOG scene has no path to slow along")
    return chosen


def path_figures(scene: Scene, traj: Trajectory) -> dict[str, float | None]:
    """A path run's ``nominal_duration`` (its schedule at full speed, s), ``path_duration``
    (how long the run took to follow it, before the stop, s) and ``max_deviation`` (the
    tool's largest distance from the path, m, :func:`~dvqp.motion.schedule.path_deviation`);
    all None for a JOG scene."""
    if scene.path is None or not traj.t.shape[0]:
        return {"nominal_duration": None, "path_duration": None, "max_deviation": None}
    reference = scene_commands(scene).reference
    moving = traj.brake_start if traj.brake_start >= 0 else traj.n_steps
    return {
        "nominal_duration": (reference.shape[0] - 1) * scene.dt,
        "path_duration": float(traj.t[moving]),
        "max_deviation": float(path_deviation(reference, traj.tool).max()),
    }


def backend_settings(
    scene: Scene, backend: str, options: dict[str, Any] | None = None, tier: str = "default"
) -> dict[str, Any]:
    """The settings a run of ``scene`` gives ``backend``: the ``tier``'s
    (:mod:`solvers.tiers`), under the scene's ``[solvers.<backend>]``, under ``options``."""
    return {
        **tier_options(backend, tier),
        **scene.solver_options.get(backend, {}),
        **(options or {}),
    }


def check_run(scene: Scene, traj: Trajectory, limits: Sequence[Limit] = ()) -> None:
    """Raise if a planned run failed: steps that failed, a broken limit, a path's end missed,
    or a limit the start broke (kept no worse, yet past its bound: :attr:`Trajectory.start_broken`).

    The path's end is reached when the final position error is within ``path.tolerance`` (m)
    and the heading error within ``path.heading_tolerance`` (rad). ``limits``: those given to
    :func:`plan` beyond the scene's own, so that a broken one is named.

    Raises
    ------
    UnreachableTargetError
        A step failed, or the path's end was not reached.
    LimitViolationError
        A saved sample breaks a limit by more than its tolerance (the baseline holds none),
        or is past a bound the start broke (then ``sample`` is 0, the start).
    """
    where = f"{scene.source}: {traj.backend}"
    started = "; ".join(start_broken_lines(traj.start_broken))
    if traj.limits_kept.shape[0] and not traj.limits_kept.all():
        worst = worst_sample_excess(scene, traj, limits)
        if worst is None or not worst[1].broken:  # a limit given to plan, not to check_run
            sample = int(np.argmin(traj.limits_kept))
            detail = f" at t = {traj.t[sample]:.3f} s (one given to plan and not named here)"
        else:
            sample = worst[0]
            detail = f": worst at t = {traj.t[sample]:.3f} s, {worst[1].describe()}"
        count = int(np.sum(~traj.limits_kept))
        also = f"; it starts outside its limits: {started}" if started else ""
        raise LimitViolationError(
            f"{where}: {count} of {traj.t.shape[0]} samples break a limit{detail}{also}",
            sample,
            float(traj.limit_excess[sample]),
        )
    too_fast = _too_fast(scene, traj)
    if too_fast is not None:
        raise LimitViolationError(f"{where}: {too_fast[2]}", too_fast[0], too_fast[1])
    if not traj.ok:
        first = int(np.argmin(traj.success))
        count = int(np.sum(~traj.success))
        raise UnreachableTargetError(
            f"{where}: {count} of {traj.n_steps} steps failed, first at t = {traj.t[first]:.3f} s "
            f"({traj.status[first]})",
            step=first,
        )
    unfinished = _unfinished(scene, traj)
    if unfinished is not None:
        raise UnreachableTargetError(f"{where}: {unfinished}", step=traj.n_steps)
    position, heading = final_errors(traj) if traj.tracking_error.shape[0] else (0.0, 0.0)
    if scene.path is not None and (
        position > scene.path.tolerance or heading > scene.path.heading_tolerance
    ):
        raise UnreachableTargetError(
            f"{where}: target not reached at t = {traj.t[-1]:.3f} s: tracking error "
            f"{position * 1e3:.3g} mm / {heading:.3g} rad (tolerance "
            f"{scene.path.tolerance * 1e3:.3g} mm / {scene.path.heading_tolerance:.3g} rad)",
            step=traj.n_steps,
            error=position,
        )
    if traj.start_broken:
        worst = max(traj.start_broken, key=lambda b: b.excess.ratio).excess
        raise LimitViolationError(f"{where}: starts outside its limits: {started}", 0, worst.value)


SPEED_TOLERANCE = 1e-6
"""rad/s: a step's joint speed past ``qd_max`` by more than this breaks the velocity limit."""


def _too_fast(scene: Scene, traj: Trajectory) -> tuple[int, float, str] | None:
    """The first sample whose step breaks a joint's velocity limit, the excess (rad/s) and
    what to say; None if every step keeps it (the baseline's steps are not held to it)."""
    over = np.abs(traj.qdot) - scene.robot.qd_max
    if not over.size or over.max() <= SPEED_TOLERANCE:
        return None
    k, joint = np.unravel_index(int(np.argmax(over)), over.shape)
    count = int(np.sum(over.max(axis=1) > SPEED_TOLERANCE))
    return (
        int(k),
        float(over[k, joint]),
        (
            f"{count} of {traj.n_steps} steps break a joint velocity limit: worst at t = "
            f"{traj.t[k]:.3f} s, joint{joint + 1} at {abs(traj.qdot[k, joint]):.4g} rad/s "
            f"(qd_max {scene.robot.qd_max[joint]:.4g})"
        ),
    )


def _unfinished(scene: Scene, traj: Trajectory) -> str | None:
    """Why a time-scaled run did not finish its path (None: it did, or it was not one)."""
    if scene.path is None or not traj.path_time.size:
        return None
    nominal = scene.dt * (scene_commands(scene).reference.shape[0] - 1)
    if traj.path_time[-1] >= nominal - 1e-6 * scene.dt:
        return None
    return (
        f"the path was not finished: {traj.path_time[-1] / nominal:.0%} of it in "
        f"{traj.t[-1]:.3f} s (the limits held the tool back; at most "
        f"{MAX_SLOWDOWN:g}x the nominal {nominal:.3f} s)"
    )
