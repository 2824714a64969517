"""Collects the samples and steps of a run into preallocated arrays, then a Trajectory.

The samples (configuration, tool, body points, objective, clearances, tilt, the lowest link
chords, the worst exact limit excess) are written by the compiled step as it concludes each
state it reaches (:class:`~dvqp.step.arrays.RecordArrays`); the steps (velocity, status,
times) here.
"""

from __future__ import annotations

import numpy as np

from dvqp.limits.excess import StartBroken
from dvqp.motion.trajectory import Trajectory
from dvqp.step import Advance

PER_SAMPLE = (
    "w",
    "min_clearance",
    "probe_clearance",
    "tilt",
    "self_distance",
    "limit_excess",
    "link_height",
    "holder_height",
)
PER_STEP = ("solve_time", "solver_time", "step_time", "task_error")


class TrajectoryRecorder:
    """Storage for ``N + 1`` samples and the ``N = n_steps`` steps between them, of an arm of
    ``n_joints`` joints and ``n_points`` body points (and its rail point's ``[l, z, h]`` if
    ``rail``), its hard tasks in ``levels`` levels."""

    def __init__(
        self, n_steps: int, n_joints: int, n_points: int, rail: bool = False, levels: int = 1
    ) -> None:
        self.arrays: dict[str, np.ndarray] = {
            "level_error": np.zeros((n_steps, levels)),
            "q": np.zeros((n_steps + 1, n_joints)),
            "qdot": np.zeros((n_steps, n_joints)),
            "tool": np.zeros((n_steps + 1, 4)),
            "points": np.zeros((n_steps + 1, n_points, 3)),
            "rail": np.zeros((n_steps + 1 if rail else 0, 3)),
            **{name: np.zeros(n_steps + 1) for name in PER_SAMPLE},
            **{name: np.zeros(n_steps) for name in PER_STEP},
            "iterations": np.full(n_steps, -1, dtype=np.int64),
            "substeps": np.ones(n_steps, dtype=np.int64),
            "success": np.zeros(n_steps, dtype=bool),
            "limits_kept": np.ones(n_steps + 1, dtype=bool),
        }
        self.status = np.full(n_steps, "", dtype=object)  # preallocated: no growth per step
        self.steps = 0
        """Steps recorded so far: the index of the step being taken."""

    def step(self, k: int, moved: Advance, step_time: float) -> None:
        """Step k (from sample k to k + 1) and its full wall time, s."""
        a, step = self.arrays, moved.step
        self.steps = k + 1
        a["solve_time"][k], a["step_time"][k] = step.solve_time, step_time
        a["solver_time"][k] = step.solver_time
        a["task_error"][k], a["success"][k] = step.task_error, step.success
        a["level_error"][k] = step.task_error if step.level_error is None else step.level_error
        a["iterations"][k] = -1 if step.iterations is None else step.iterations
        a["substeps"][k] = moved.substeps
        self.status[k] = step.status
        if step.success:
            a["qdot"][k] = step.qdot

    def extend(self, steps: int) -> None:
        """Room for ``steps`` more steps and their samples, those recorded kept (new arrays:
        hand them to the stepper, :meth:`~dvqp.step.Stepper.record_into`)."""
        for name, a in self.arrays.items():
            if a.shape[0] == 0:  # not recorded (no rail point)
                continue
            room = np.zeros((steps, *a.shape[1:]), dtype=a.dtype)
            self.arrays[name] = np.concatenate([a, room])
        self.status = np.concatenate([self.status, np.full(steps, "", dtype=object)])

    def trajectory(
        self,
        dt: float,
        pipe_radius: float,
        backend: str,
        steps: int | None = None,
        brake_start: int = -1,
        start_broken: tuple[StartBroken, ...] = (),
        refusals: dict[str, int] | None = None,
        accuracy: dict[str, float] | None = None,
        levels: tuple[str, ...] = (),
    ) -> Trajectory:
        """The first ``steps`` (default all) recorded steps and their samples (l and α
        unwrapped), with ``qddot``: the change of joint velocity at the start of each step over
        dt (the run starts at rest), rad/s²; ``brake_start`` the first braking step (−1: none);
        the limits the start broke (:meth:`dvqp.step.Stepper.start_broken`); the backend calls
        refused, by kind (:attr:`dvqp.resolution.qp.QPSolver.refusals`), and their accuracy
        (:meth:`solvers.accuracy.AccuracyTally.to_dict`); the names of the levels of its hard
        tasks (priority order)."""
        n = self.arrays["qdot"].shape[0]
        steps = n if steps is None else steps
        kept = {name: a[: max(steps + a.shape[0] - n, 0)] for name, a in self.arrays.items()}
        qdot = kept["qdot"]
        before = np.vstack([np.zeros((1, qdot.shape[1])), qdot[:-1]])
        return Trajectory.from_samples(
            dt=dt,
            pipe_radius=pipe_radius,
            backend=backend,
            status=self.status[:steps],
            qddot=(qdot - before) / dt,
            brake_start=brake_start,
            start_broken=start_broken,
            refusals=dict(refusals or {}),
            accuracy=dict(accuracy or {}),
            levels=tuple(levels),
            **kept,
        )
