"""Offline trajectory generation from a :class:`~dvqp.scenes.scene.Scene`.

:func:`plan` runs a scene's motion with a named backend: ``"pinv"`` is the paper's baseline
(:class:`~dvqp.resolution.pinv.PseudoinverseResolver`), any other name a QP backend of :mod:`solvers`
behind :class:`~dvqp.resolution.qp_resolver.QPResolver`. In JOG mode the tool gets the JOG velocities;
in path mode it follows the waypoints with position feedback ``ẋ = ẋ_d + K(x_d − x)``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.errors import BackendError, ParameterError, UnreachableTargetError
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.qp_resolver import QPResolver
from dvqp.resolution.qp import StepConfig
from dvqp.resolution.step import Resolver
from dvqp.scenes.scene import PathMotion, Scene
from dvqp.motion.simulate import MAX_STEPS, dv_error, jog_commands, simulate
from dvqp.kinematics.state import KinematicState
from dvqp.motion.trajectory import Trajectory

PINV = "pinv"
"""Name of the pseudoinverse baseline."""


def available_backends() -> list[str]:
    """Every backend name :func:`plan` accepts here: ``pinv`` first, then the QP backends."""
    return [PINV, *solvers.available_backends()]


def default_backends() -> list[str]:
    """``pinv`` and every installed plain QP backend name (no ``qpsolvers:`` prefix)."""
    return [PINV, *(b for b in solvers.available_backends() if ":" not in b)]


def make_resolver(scene: Scene, backend: str) -> Resolver:
    """A fresh resolver for a scene.

    Raises
    ------
    BackendError
        Unknown or not installed; the message lists the installed names.
    """
    if backend == PINV:
        return PseudoinverseResolver(scene.weights)
    if backend not in solvers.available_backends():
        installed = ", ".join(available_backends())
        raise BackendError(f"unknown backend {backend!r}; installed: {installed}")
    # the objective's ObstacleSet: the per-state proximity cache is then shared with the dampers
    config = StepConfig(scene.robot, scene.objective.obstacles, scene.dampers, scene.weights)
    return QPResolver(config, backend)


@dataclass(frozen=True)
class Motion:
    """The sampled motion of a scene.

    Attributes
    ----------
    commands : ndarray, shape (N, 4)
        Feed-forward tool DV velocities ``ẋ_d`` per step (m/s, m/s, m/s, rad/s).
    reference : ndarray, shape (N+1, 4)
        ``x_d(t_k)``, l and α unwrapped: the path, or in JOG mode the start plus the
        integrated commands.
    feedback_gain : float
        ``K``, 1/s (0 in JOG mode: the paper's JOG uses velocities only).
    """

    commands: NDArray[np.float64]
    reference: NDArray[np.float64]
    feedback_gain: float


def motion(scene: Scene) -> Motion:
    """Sample a scene's JOG segments or path every ``scene.dt``."""
    tool0 = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius).tool
    if scene.path is None:
        cmd = jog_commands(scene.jog, scene.dt)
        ref = tool0 + np.vstack([np.zeros(4), np.cumsum(cmd * scene.dt, axis=0)])
        return Motion(cmd, ref, 0.0)
    ref = path_reference(scene.path, tool0, scene.dt, scene.pipe_radius)
    return Motion(np.diff(ref, axis=0) / scene.dt, ref, scene.path.gain)


def path_reference(
    path: PathMotion, start: NDArray[np.float64], dt: float, radius: float
) -> NDArray[np.float64]:
    """``x_d(t_k)``: constant speed along the (l, z, h) polyline from ``start``.

    The waypoints are shifted by whole turns (2πR in l, 2π in α) so the first lies nearest the
    tool's start; the tool first moves from ``start`` to it, then along the waypoints. α is
    interpolated linearly along the arc length.

    Parameters
    ----------
    path
        Waypoints, speed.
    start
        The tool's DV position at ``q0``, shape (4,).
    dt
        Step, s.
    radius
        Pipe radius, m.

    Returns
    -------
    ndarray, shape (N+1, 4)
        ``N = ⌈length / (speed·dt)⌉``; the last row is the last waypoint.
    """
    wp = np.array(path.waypoints, dtype=float)
    wp[:, 0] += start[0] + wrap(wp[0, 0] - start[0], radius) - wp[0, 0]
    wp[:, 3] += start[3] + wrap_angle(wp[0, 3] - start[3]) - wp[0, 3]
    nodes = np.vstack([start, wp])
    seg = PathMotion.segment_lengths(nodes)
    keep = np.concatenate([[True], seg > 0.0])
    nodes, s = nodes[keep], np.concatenate([[0.0], np.cumsum(seg[seg > 0.0])])
    n_steps = max(1, math.ceil(s[-1] / (path.speed * dt) - 1e-9))
    if n_steps > MAX_STEPS:
        raise ParameterError("motion.path", f"{n_steps} steps is too many (at most {MAX_STEPS})")
    arc = np.minimum(path.speed * dt * np.arange(n_steps + 1), s[-1])
    return np.column_stack([np.interp(arc, s, nodes[:, c]) for c in range(4)])


def plan(
    scene: Scene, backend: str = "daqp", progress: Callable[[int, int], None] | None = None
) -> Trajectory:
    """Run a scene with a backend and return its trajectory.

    The trajectory carries the scene text and ``tracking_error`` (``x_d − x`` per sample,
    l and α wrapped). A run whose steps failed or whose path ends off target is returned as
    well; :func:`failure` says whether and why it failed.

    Parameters
    ----------
    scene
        The scene.
    backend
        ``"pinv"`` or a name of :func:`solvers.available_backends`.
    progress
        Called as ``progress(k, N)`` after each step.

    Raises
    ------
    BackendError
        Unknown backend.
    SingularConfigurationError
        The baseline met a singular task Jacobian.
    """
    resolver = make_resolver(scene, backend)
    m = motion(scene)
    traj = simulate(
        scene.robot, scene.pipe_radius, scene.objective, resolver, scene.q0, m.commands,
        scene.dt, reference=m.reference[:-1] if m.feedback_gain > 0 else None,
        feedback_gain=m.feedback_gain, progress=progress,
    )  # fmt: skip
    error = dv_error(m.reference, traj.dv, scene.pipe_radius)
    return dataclasses.replace(traj, tracking_error=error, scene_text=scene.text)


def failure(scene: Scene, traj: Trajectory) -> UnreachableTargetError | None:
    """Why a planned run failed, or None: steps that failed, or a path's end not reached.

    The path's end counts as reached when the final position error is within
    ``path.tolerance`` (m) and the heading error within ``path.heading_tolerance`` (rad).
    """
    where = f"{scene.source}: {traj.backend}"
    if not traj.ok:
        first = int(np.argmin(traj.success))
        count = int(np.sum(~traj.success))
        return UnreachableTargetError(
            f"{where}: {count} of {traj.n_steps} steps failed, first at t = {traj.t[first]:.3f} s "
            f"({traj.status[first]})",
            step=first,
        )
    if scene.path is None or traj.tracking_error.shape[0] == 0:
        return None
    position, heading = final_errors(traj)
    if position > scene.path.tolerance or heading > scene.path.heading_tolerance:
        return UnreachableTargetError(
            f"{where}: target not reached at t = {traj.t[-1]:.3f} s: tracking error "
            f"{position * 1e3:.3g} mm / {heading:.3g} rad (tolerance "
            f"{scene.path.tolerance * 1e3:.3g} mm / {scene.path.heading_tolerance:.3g} rad)",
            step=traj.n_steps,
            error=position,
        )
    return None


def final_errors(traj: Trajectory) -> tuple[float, float]:
    """Final tracking error: largest of |l|, |z|, |h| (m) and |α| (rad)."""
    last = traj.tracking_error[-1]
    return float(np.max(np.abs(last[:3]))), float(abs(last[3]))
