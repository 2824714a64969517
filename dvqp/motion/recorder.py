"""Collects the samples and steps of a run into preallocated arrays, then a Trajectory."""

from __future__ import annotations

import math

import numpy as np

from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import proximity
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import Excess
from dvqp.limits.self_collision import self_distance
from dvqp.limits.tilt import tilt
from dvqp.motion.advance import Advance
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.step import Step

PER_SAMPLE = ("w", "min_clearance", "probe_clearance", "tilt", "self_distance", "limit_excess")
PER_STEP = ("solve_time", "solver_time", "step_time", "task_error")


class TrajectoryRecorder:
    """Storage for ``N + 1`` samples and the ``N`` steps between them.

    Parameters
    ----------
    n_steps
        N.
    n_joints
        n.
    n_points
        Number of body points k.
    obstacles
        The obstacles whose clearances are recorded.
    """

    def __init__(self, n_steps: int, n_joints: int, n_points: int, obstacles: ObstacleSet) -> None:
        self.obstacles = obstacles
        self.arrays: dict[str, np.ndarray] = {
            "q": np.empty((n_steps + 1, n_joints)),
            "qdot": np.zeros((n_steps, n_joints)),
            "tool": np.empty((n_steps + 1, 4)),
            "points": np.empty((n_steps + 1, n_points, 3)),
            **{name: np.empty(n_steps + 1) for name in PER_SAMPLE},
            **{name: np.zeros(n_steps) for name in PER_STEP},
            "iterations": np.full(n_steps, -1, dtype=np.int64),
            "substeps": np.ones(n_steps, dtype=np.int64),
            "success": np.zeros(n_steps, dtype=bool),
            "compiled": np.zeros(n_steps, dtype=bool),
            "limits_kept": np.ones(n_steps + 1, dtype=bool),
        }
        self.status = np.full(n_steps, "", dtype=object)  # preallocated: no growth per step

    def sample(self, k: int, state: KinematicState, w: float, excess: Excess) -> None:
        """Sample k: configuration, tool and body points, objective value, clearances, tilt,
        and the worst exact limit excess there."""
        a = self.arrays
        a["q"][k], a["tool"][k], a["points"][k] = state.q, state.tool, state.points
        a["w"][k] = w
        a["limit_excess"][k] = max(excess.value, 0.0)
        a["limits_kept"][k] = not excess.broken
        a["tilt"][k] = tilt(state)
        a["self_distance"][k] = self_distance(state)[0]
        if len(self.obstacles):
            near = proximity(state, self.obstacles)
            a["min_clearance"][k], a["probe_clearance"][k] = (
                near.min_clearance(),
                near.probe_clearance(),
            )
        else:
            a["min_clearance"][k] = a["probe_clearance"][k] = math.inf

    def sample_values(
        self, k: int, q: np.ndarray, tool: np.ndarray, guarded: np.ndarray, w: float,
        excess: float, kept: bool, diagnostics: np.ndarray,
    ) -> None:  # fmt: skip
        """Sample k from the compiled step's buffers: ``guarded`` (k+1, 3) (the body points
        then the probe), the worst excess value, and ``diagnostics`` = ``[tilt, self distance,
        min clearance, probe clearance]``."""
        a = self.arrays
        a["q"][k], a["tool"][k], a["points"][k] = q, tool, guarded[:-1]
        a["w"][k] = w
        a["limit_excess"][k] = max(excess, 0.0)
        a["limits_kept"][k] = kept
        a["tilt"][k], a["self_distance"][k] = diagnostics[0], diagnostics[1]
        a["min_clearance"][k], a["probe_clearance"][k] = diagnostics[2], diagnostics[3]

    def step(self, k: int, advance: Advance, step_time: float) -> None:
        """Step k (from sample k to k + 1) and its full wall time, s."""
        step = advance.step
        self.step_values(k, step, advance.substeps, step_time)

    def step_values(
        self, k: int, step: Step, substeps: int, step_time: float, compiled: bool = False
    ) -> None:
        """Step k from its :class:`~dvqp.resolution.step.Step` (or anything with the same
        fields), its substeps, its full wall time (s) and whether the compiled path took it."""
        a = self.arrays
        a["compiled"][k] = compiled
        a["solve_time"][k], a["step_time"][k] = step.solve_time, step_time
        a["solver_time"][k] = step.solver_time
        a["task_error"][k], a["success"][k] = step.task_error, step.success
        a["iterations"][k] = -1 if step.iterations is None else step.iterations
        a["substeps"][k] = substeps
        self.status[k] = step.status
        if step.success:
            a["qdot"][k] = step.qdot

    def trajectory(self, dt: float, pipe_radius: float, backend: str) -> Trajectory:
        """The recorded run (l and α unwrapped), with ``qddot``: the change of joint velocity
        at the start of each step over dt (the run starts at rest), rad/s²."""
        qdot = self.arrays["qdot"]
        before = np.vstack([np.zeros((1, qdot.shape[1])), qdot[:-1]])
        return Trajectory.from_samples(
            dt=dt, pipe_radius=pipe_radius, backend=backend, status=self.status,
            qddot=(qdot - before) / dt, **self.arrays,
        )  # fmt: skip
