"""What was driven in the console: samples and steps kept in a bounded ring, then a Trajectory.

Every step the console makes is recorded as ``plan`` records it (the same arrays, see
:class:`dvqp.motion.recorder.TrajectoryRecorder`), except idle ones: no command and the arm
at rest. The ring keeps the last :data:`MAX_RECORD_SECONDS` of driven motion; older steps are
dropped from the front, so a saved file always starts at a sample and every step joins two
consecutive samples.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.proximity import link_label, point_label
from dvqp.motion.simulate import dv_error
from dvqp.motion.trajectory import Trajectory
from dvqp.step import Advance, Stepper

MAX_RECORD_SECONDS = 300.0
"""Driven motion kept for "save", s of simulated time (the most recent)."""

IDLE_MOTION = 1e-9
"""Largest joint motion (rad) of a step without command that is not recorded."""

SCALARS = ("w", "min_clearance", "probe_clearance", "tilt", "self_distance", "limit_excess",
           "limits_kept")  # fmt: skip
STEP_SCALARS = ("solve_time", "solver_time", "step_time", "task_error", "iterations", "success",
                "substeps")  # fmt: skip


@dataclass(frozen=True)
class Sample:
    """What the console shows and records of one configuration.

    Attributes
    ----------
    q, tool, points : ndarray, shapes (n,), (4,), (k, 3)
        The configuration (rad), the tool ``[l, z, h, α]`` and the body points ``[l, z, h]``.
    w : float
        Objective value.
    min_clearance, probe_clearance : float
        Smallest clearance of any guarded part, of the probe and its holder, m (inf: none).
    closest : str or None
        ``"<part>/obstacle<j>"`` that has ``min_clearance`` (None without obstacles).
    tilt : float
        Probe axis from the radial direction, rad.
    self_distance : float
        Smallest distance between non-adjacent guarded links, m (inf: none).
    excess : float
        Worst exact limit excess here (its unit), against the start.
    kept : bool
        Every limit is kept here (to its tolerance).
    """

    q: NDArray[np.float64]
    tool: NDArray[np.float64]
    points: NDArray[np.float64]
    w: float
    min_clearance: float
    probe_clearance: float
    closest: str | None
    tilt: float
    self_distance: float
    excess: float
    kept: bool

    @classmethod
    def of(cls, stepper: Stepper) -> Sample:
        """The state ``stepper`` has loaded (copied)."""
        a, k = stepper.arrays, stepper.robot.n_points
        tilt, apart, clearance, probe, closest = (float(v) for v in a.diagnostics)
        where = None
        if closest >= 0:
            obstacle, part = divmod(int(closest), 2 * k + 1)
            name = point_label(part, k) if part <= k else link_label(part - k - 1, k)
            where = f"{name}/obstacle{obstacle + 1}"
        excess = stepper.excess_now
        return cls(a.state.q.copy(), a.state.tool.copy(), a.state.guarded[:-1].copy(),
                   float(a.objective.value[0]), clearance, probe, where, tilt, apart,
                   float(excess[0]), bool(excess[1] <= 1.0))  # fmt: skip

    def row(self) -> NDArray[np.float64]:
        """Packed: q, tool, points, then :data:`SCALARS`."""
        scalars = [
            self.w,
            self.min_clearance,
            self.probe_clearance,
            self.tilt,
            self.self_distance,
            max(self.excess, 0.0),
            1.0 if self.kept else 0.0,
        ]
        return np.concatenate([self.q, self.tool, self.points.ravel(), scalars])


class Recording:
    """A bounded record of the driven samples and the steps between them.

    Parameters
    ----------
    first : Sample
        The sample the record starts from.
    dt : float
        Step, s.
    """

    def __init__(self, first: Sample, dt: float) -> None:
        self.dt, self.n, self.k = dt, first.q.shape[0], first.points.shape[0]
        limit = max(1, int(MAX_RECORD_SECONDS / dt))
        self.samples: deque[NDArray[np.float64]] = deque([first.row()], maxlen=limit + 1)
        self.steps: deque[tuple[NDArray[np.float64], str]] = deque(maxlen=limit)

    def add(
        self, before: Sample, moved: Advance, after: Sample, command: NDArray, took: float
    ) -> bool:
        """Record a step and the sample it reached, unless it is idle; True if recorded."""
        motion = float(np.max(np.abs(after.q - before.q)))
        if not np.any(command) and motion <= IDLE_MOTION and moved.step.success:
            return False
        step = moved.step
        iterations = -1 if step.iterations is None else step.iterations
        qdot = step.qdot if step.success else np.zeros(self.n)
        scalars = [step.solve_time, step.solver_time, took, step.task_error, iterations,
                   step.success, moved.substeps]  # fmt: skip
        self.steps.append((np.concatenate([qdot, command, scalars]), step.status))
        self.samples.append(after.row())
        return True

    def copy(self) -> Recording:
        """An independent copy (for saving while the arm moves on)."""
        copy = Recording.__new__(Recording)
        copy.dt, copy.n, copy.k = self.dt, self.n, self.k
        copy.samples, copy.steps = self.samples.copy(), self.steps.copy()
        return copy

    def __len__(self) -> int:
        """Steps recorded."""
        return len(self.steps)

    def trajectory(self, pipe_radius: float, backend: str, scene_text: str) -> Trajectory:
        """The record as a full :class:`Trajectory` (``dvqp plot`` reads its ``.npz``)."""
        n, k = self.n, self.k
        rows = np.array(self.samples)
        steps = np.array([s for s, _ in self.steps]).reshape(
            len(self.steps), n + 4 + len(STEP_SCALARS)
        )
        q, tool = rows[:, :n], rows[:, n : n + 4]
        points = rows[:, n + 4 : n + 4 + 3 * k].reshape(-1, k, 3)
        sample = dict(zip(SCALARS, rows[:, n + 4 + 3 * k :].T, strict=True))
        per_step = dict(zip(STEP_SCALARS, steps[:, n + 4 :].T, strict=True))
        qdot = steps[:, :n]
        before = np.vstack([np.zeros((1, n)), qdot[:-1]])  # the record starts at rest
        arrays = {name: _typed(name, v) for name, v in {**sample, **per_step}.items()}
        traj = Trajectory.from_samples(
            dt=self.dt, pipe_radius=pipe_radius, backend=backend, tool=tool, points=points,
            status=[status for _, status in self.steps], q=q, qdot=qdot,
            qddot=(qdot - before) / self.dt, **arrays,
        )  # fmt: skip
        commands = steps[:, n : n + 4]
        reference = traj.tool[0] + np.vstack([np.zeros(4), np.cumsum(commands * self.dt, axis=0)])
        error = dv_error(reference, traj.tool, pipe_radius)
        return dataclasses.replace(traj, tracking_error=error, scene_text=scene_text)


def _typed(name: str, values: NDArray[np.float64]) -> NDArray[Any]:
    """A packed column as the trajectory stores it: flags as bool, counts as int64."""
    if name in ("limits_kept", "success"):
        return values > 0.5
    if name in ("iterations", "substeps"):
        return values.astype(np.int64)
    return values
