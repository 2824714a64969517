"""What a planned run's saved samples show: its worst limit excess, recomputed exactly from
the samples, and its final tracking error."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dvqp.limits import Excess, Limit
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.scenes.scene import Scene
from dvqp.step import Stepper


def worst_sample_excess(
    scene: Scene, traj: Trajectory, limits: Sequence[Limit] = ()
) -> tuple[int, Excess] | None:
    """The sample whose limit excess is worst relative to its tolerance, and that excess; None
    if no sample exceeds a limit (or the file, from before 0.2, records no excess)."""
    candidates = np.flatnonzero(traj.limit_excess > 0.0)
    if candidates.shape[0] == 0:
        return None
    spec = scene.spec().with_extra(limits=limits)
    stepper = Stepper(
        scene.robot, scene.pipe_radius, PseudoinverseResolver(spec), traj.q[0], scene.dt
    )
    stepper.start(traj.q[0])
    found = []
    for k in candidates[np.argsort(traj.limit_excess[candidates])[-20:]]:
        if stepper.load(traj.q[k]):
            found.append((int(k), stepper.excess()))
    return max(found, key=lambda item: item[1].ratio) if found else None


def final_errors(traj: Trajectory) -> tuple[float, float]:
    """Final tracking error: largest of |l|, |z|, |h| (m) and |α| (rad)."""
    last = traj.tracking_error[-1]
    return float(np.max(np.abs(last[:3]))), float(abs(last[3]))
