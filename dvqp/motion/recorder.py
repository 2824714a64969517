"""Collects the samples and steps of a run into preallocated arrays, then a Trajectory."""

from __future__ import annotations

import numpy as np

from dvqp.kinematics.state import KinematicState
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.step import Step


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
    """

    def __init__(self, n_steps: int, n_joints: int, n_points: int) -> None:
        self.n_steps = n_steps
        self.q = np.empty((n_steps + 1, n_joints))
        self.qdot = np.zeros((n_steps, n_joints))
        self.tool = np.empty((n_steps + 1, 4))
        self.points = np.empty((n_steps + 1, n_points, 3))
        self.w = np.empty(n_steps + 1)
        self.min_clearance = np.empty(n_steps + 1)
        self.solve_time = np.zeros(n_steps)
        self.step_time = np.zeros(n_steps)
        self.task_error = np.zeros(n_steps)
        self.iterations = np.full(n_steps, -1, dtype=np.int64)
        self.success = np.zeros(n_steps, dtype=bool)
        self.status: list[str] = []

    def sample(self, k: int, state: KinematicState, w: float, clearance: float) -> None:
        """Sample k: configuration, tool and body points, objective value, clearance (m)."""
        self.q[k], self.tool[k], self.points[k] = state.q, state.tool, state.points
        self.w[k] = w
        self.min_clearance[k] = clearance

    def step(self, k: int, step: Step, step_time: float) -> None:
        """Step k (from sample k to k + 1) and its full wall time, s."""
        self.solve_time[k], self.step_time[k] = step.solve_time, step_time
        self.task_error[k], self.success[k] = step.task_error, step.success
        self.iterations[k] = -1 if step.iterations is None else step.iterations
        self.status.append(step.status)
        if step.success:
            self.qdot[k] = step.qdot

    def trajectory(self, dt: float, pipe_radius: float, backend: str) -> Trajectory:
        """The recorded run (l and α unwrapped)."""
        return Trajectory.from_samples(
            dt=dt, q=self.q, qdot=self.qdot, tool=self.tool, points=self.points,
            pipe_radius=pipe_radius, w=self.w, min_clearance=self.min_clearance,
            solve_time=self.solve_time, step_time=self.step_time, task_error=self.task_error,
            iterations=self.iterations, success=self.success, status=self.status,
            backend=backend,
        )  # fmt: skip
