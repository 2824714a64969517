"""What was driven in the console: samples and steps kept in a bounded ring, then a Trajectory.

Every step the console makes is recorded as ``plan`` records it (by a
:class:`dvqp.motion.recorder.TrajectoryRecorder`), except idle ones: no command and the arm
at rest. The ring keeps the last :data:`MAX_RECORD_SECONDS` of driven motion; older steps are
dropped from the front, so a saved file always starts at a sample and every step joins two
consecutive samples.
"""

from __future__ import annotations

import copy
import dataclasses
from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.motion.recorder import PER_SAMPLE, TrajectoryRecorder
from dvqp.motion.simulate import dv_error
from dvqp.motion.trajectory import Trajectory
from dvqp.step import Advance, Stepper

MAX_RECORD_SECONDS = 300.0
"""Driven motion kept for "save", s of simulated time (the most recent)."""
IDLE_MOTION = 1e-9
"""Largest joint motion (rad) of a step without command that is not recorded."""
SAMPLED = ("q", "tool", "points", *PER_SAMPLE, "limits_kept")
"""The :class:`Sample` fields a trajectory holds per sample."""


@dataclass(frozen=True)
class Sample:
    """What the console shows and records of one configuration: the values a
    :class:`Trajectory` holds per sample, under the same names and in the same units (l and α
    not unwrapped), and ``closest``, the ``"<part>/<obstacle>"`` that has ``min_clearance``
    (None: no obstacle)."""

    q: NDArray[np.float64]
    tool: NDArray[np.float64]
    points: NDArray[np.float64]
    w: float
    min_clearance: float
    probe_clearance: float
    closest: str | None
    tilt: float
    self_distance: float
    limit_excess: float
    limits_kept: bool
    link_height: float
    holder_height: float

    @classmethod
    def of(cls, stepper: Stepper) -> Sample:
        """The state ``stepper`` has loaded (copied)."""
        a, k, names = stepper.arrays, stepper.robot.n_points, stepper.robot.part_names
        tilt, apart, clearance, probe, closest, low, holder = (float(v) for v in a.diagnostics)
        where = None
        if closest >= 0:
            m = a.near.point_distance.shape[1]
            obstacle, part = divmod(int(closest), m + a.near.ends.shape[0])
            name = names.point(part) if part < m else names.link(part - m)
            where = f"{name}/{stepper.obstacles.labels[obstacle]}"
        excess = stepper.excess_now
        return cls(
            a.state.q.copy(),
            a.state.tool.copy(),
            a.state.guarded[:k].copy(),
            float(a.objective.value[0]),
            clearance,
            probe,
            where,
            tilt,
            apart,
            max(float(excess[0]), 0.0),
            bool(excess[1] <= 1.0),
            low,
            holder,
        )


class Recording:
    """A bounded record of the driven samples, from ``first``, and the steps of ``dt`` s
    between them."""

    def __init__(self, first: Sample, dt: float) -> None:
        self.dt = dt
        limit = max(1, int(MAX_RECORD_SECONDS / dt))
        self.samples: deque[Sample] = deque([first], maxlen=limit + 1)
        self.steps: deque[tuple[Advance, NDArray[np.float64], float]] = deque(maxlen=limit)

    def add(
        self, before: Sample, moved: Advance, after: Sample, command: NDArray, took: float
    ) -> bool:
        """Record a step (its wall time ``took``, s) and the sample it reached, unless it is
        idle; True if recorded."""
        motion = float(np.max(np.abs(after.q - before.q)))
        if not np.any(command) and motion <= IDLE_MOTION and moved.step.success:
            return False
        self.steps.append((moved, command, took))
        self.samples.append(after)
        return True

    def copy(self) -> Recording:
        """An independent copy (for saving while the arm moves on)."""
        other = copy.copy(self)
        other.samples, other.steps = self.samples.copy(), self.steps.copy()
        return other

    def __len__(self) -> int:
        """Steps recorded."""
        return len(self.steps)

    def trajectory(
        self, pipe_radius: float, backend: str, scene_text: str, levels: tuple[str, ...] = ()
    ) -> Trajectory:
        """The record as a full :class:`Trajectory` (``dvqp plot`` reads its ``.npz``); the
        step's task levels are named ``levels``."""
        first = self.samples[0]
        recorder = TrajectoryRecorder(
            len(self.steps), first.q.shape[0], first.points.shape[0], levels=max(len(levels), 1)
        )
        for name in SAMPLED:
            recorder.arrays[name][:] = [getattr(sample, name) for sample in self.samples]
        for k, (moved, _, took) in enumerate(self.steps):
            recorder.step(k, moved, took)
        traj = recorder.trajectory(self.dt, pipe_radius, backend, levels=levels)
        commands = np.reshape([command for _, command, _ in self.steps], (-1, 4))
        reference = traj.tool[0] + np.vstack([np.zeros(4), np.cumsum(commands * self.dt, axis=0)])
        error = dv_error(reference, traj.tool, pipe_radius)
        return dataclasses.replace(traj, tracking_error=error, scene_text=scene_text)
