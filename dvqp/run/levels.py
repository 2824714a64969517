"""How each level of a run's hard tasks fared: kept exactly, or given way (when, how far).

A level's residual per step (:attr:`Trajectory.level_error`, task units per s) says whether
the step kept it: at most :data:`KEPT` — the QP answers' acceptance tolerance — is kept
exactly. Its tasks say how far from what they hold the run went at every sample
(:meth:`dvqp.Task.deviation`: the tool against the commanded motion, a point or a posture
against its target), in m and rad (:func:`level_deviation`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.spec import StepSpec
from dvqp.tasks import Samples

KEPT = 1e-6
"""m/s or rad/s: a level whose residual in a step is at most this (the tolerance every QP
answer is checked to) was kept exactly in that step."""
UNITS = ("m", "rad")
"""The two kinds of error a level's deviation holds, in this order."""


def level_deviation(
    spec: StepSpec, traj: Trajectory
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Each level's worst error at every sample, ``(N+1, L, 2)`` ``[m, rad]``, and which of the
    two its tasks measure, ``(L, 2)`` (a task that does not say counts in neither)."""
    samples = Samples(traj.q, traj.tracking_error, traj.points, traj.pipe_radius)
    levels = spec.levels
    worst = np.zeros((traj.q.shape[0], len(levels), 2))
    measured = np.zeros((len(levels), 2), dtype=bool)
    for k, level in enumerate(levels):
        for task in level:
            found = task.deviation(samples)
            if found is None:
                continue
            for unit, column in zip(found.units, np.abs(found.values).T, strict=True):
                u = UNITS.index(unit)
                measured[k, u] = True
                np.maximum(worst[:, k, u], column, out=worst[:, k, u])
    return worst, measured


@dataclass(frozen=True)
class LevelFigures:
    """One level of a run: its ``name``; ``gave_way``, the steps that succeeded and did not
    keep it exactly (of ``steps``); ``worst_residual`` (task units per s); and the worst
    ``length`` (m) and ``angle`` (rad) error over the samples (None: not measured)."""

    name: str
    steps: int
    gave_way: int
    worst_residual: float
    length: float | None
    angle: float | None

    @property
    def kept(self) -> bool:
        """Kept exactly in every step that succeeded."""
        return self.gave_way == 0

    def words(self) -> str:
        """``"kept exactly; worst error 0.012 mm, 3.1e-05 rad"`` or ``"gave way in 161 of 808
        steps; worst error 15.7 mm"``."""
        state = (
            "kept exactly" if self.kept else f"gave way in {self.gave_way} of {self.steps} steps"
        )
        errors = [f"{self.length * 1e3:.3g} mm"] if self.length is not None else []
        errors += [f"{self.angle:.2g} rad"] if self.angle is not None else []
        return f"{state}; worst error {', '.join(errors)}" if errors else state


def level_figures(traj: Trajectory) -> list[LevelFigures]:
    """:class:`LevelFigures` of each level of ``traj`` (empty: a file without levels)."""
    if not traj.levels or traj.level_error.shape[0] != traj.n_steps:
        return []
    ok = traj.success
    kept = traj.level_error[ok]
    found = []
    for k, name in enumerate(traj.levels):
        column = kept[:, k]
        deviation = traj.level_deviation
        has = traj.level_measured[k] if traj.level_measured.shape[0] > k else (False, False)
        worst = [
            float(deviation[:, k, u].max()) if has[u] and deviation.shape[0] else None
            for u in range(2)
        ]
        found.append(
            LevelFigures(
                name,
                int(column.shape[0]),
                int(np.sum(column > KEPT)),
                float(column.max(initial=0.0)),
                *worst,
            )
        )
    return found
