"""What a planned run's saved samples show: its worst limit excess, recomputed exactly from
the samples, its final tracking error and whether it tracked the commanded motion."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from dvqp.limits import Excess, Limit
from dvqp.motion.path import ToolPath
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


def tracking(scene: Scene, traj: Trajectory) -> tuple[bool, float, float] | None:
    """Whether the tool followed the commanded motion: ``(tracked, position, heading)``, the
    largest tracking error of any sample in l, z, h (m) and in α (rad), tracked when both are
    within the scene path's ``tolerance`` and ``heading_tolerance`` (a JOG scene: a path's
    defaults, 5 mm and 0.05 rad); None if the trajectory records no tracking error."""
    if not traj.tracking_error.shape[0]:
        return None
    path = scene.path
    tolerance = ToolPath.tolerance if path is None else path.tolerance
    heading_tolerance = ToolPath.heading_tolerance if path is None else path.heading_tolerance
    error = np.abs(traj.tracking_error)
    position, heading = float(np.max(error[:, :3])), float(np.max(error[:, 3]))
    return position <= tolerance and heading <= heading_tolerance, position, heading
