"""How each level of a run's hard tasks fared: kept exactly, met in least squares, drifted, or
given way (when, how far).

A level's residual per step (:attr:`Trajectory.level_error`, task units per s) says whether
the step met it: at most :data:`KEPT` — the QP answers' acceptance tolerance — is met
exactly. Above it, the step either met it in least squares — as well as the levels above let
it with no limit binding: a level that cannot be met exactly (a posture below other tasks), in
a step not relaxed (the baseline's steps hold no limit: never relaxed) — or it gave way (a
relaxed step: a limit pushed it off). Its tasks say how far from what they hold the run went
at every sample (:meth:`dvqp.Task.deviation`: the tool against the commanded motion, a point
or a posture against its target), in m and rad (:func:`level_deviation`): a level met in
every step is *kept exactly* only if that error stayed within :data:`DRIFT_LENGTH` and
:data:`DRIFT_ANGLE` (the report says so), else it *drifted* (met per step, not in position).
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
DRIFT_LENGTH = 5e-5
"""m: the integrated error within which a level met in every step counts as kept exactly."""
DRIFT_ANGLE = 1e-4
"""rad: the same in angle."""
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
    """One level of a run: its ``name``; ``gave_way``, the steps that succeeded, were relaxed
    and did not meet it exactly (of ``steps``); ``least_squares``, those that met it in least
    squares (not relaxed, not met exactly); ``worst_residual`` (task units per s); and the
    worst ``length`` (m) and ``angle`` (rad) error over the samples (None: not measured)."""

    name: str
    steps: int
    gave_way: int
    worst_residual: float
    length: float | None
    angle: float | None
    least_squares: int = 0

    @property
    def met(self) -> bool:
        """Met exactly in every step that succeeded."""
        return self.gave_way == 0 and self.least_squares == 0

    @property
    def drifted(self) -> bool:
        """Met exactly in every step, but its integrated error went past :data:`DRIFT_LENGTH`
        or :data:`DRIFT_ANGLE`."""
        over_length = self.length is not None and self.length > DRIFT_LENGTH
        return self.met and (over_length or (self.angle is not None and self.angle > DRIFT_ANGLE))

    @property
    def kept(self) -> bool:
        """Met exactly in every step that succeeded and within the drift tolerances."""
        return self.met and not self.drifted

    def words(self) -> str:
        """``"kept exactly (within 0.05 mm, 0.1 mrad); worst error 0.012 mm, 3.1e-05 rad"``,
        ``"met exactly per step but drifted; worst error 0.87 mm, 0.0022 rad (kept exactly:
        within 0.05 mm, 0.1 mrad)"``, ``"met in least squares in 339 of 340 steps; worst error
        0.12 rad"`` or ``"gave way in 161 of 808 steps; worst error 15.7 mm"``."""
        within = f"within {DRIFT_LENGTH * 1e3:g} mm, {DRIFT_ANGLE * 1e3:g} mrad"
        if self.kept:
            state = f"kept exactly ({within})"
        elif self.drifted:
            state = "met exactly per step but drifted"
        else:
            parts = [f"gave way in {self.gave_way} of {self.steps} steps"] if self.gave_way else []
            if self.least_squares:
                parts.append(f"met in least squares in {self.least_squares} of {self.steps} steps")
            state = ", ".join(parts)
        errors = [f"{self.length * 1e3:.3g} mm"] if self.length is not None else []
        errors += [f"{self.angle:.2g} rad"] if self.angle is not None else []
        text = f"{state}; worst error {', '.join(errors)}" if errors else state
        return f"{text} (kept exactly: {within})" if self.drifted else text


def level_figures(traj: Trajectory) -> list[LevelFigures]:
    """:class:`LevelFigures` of each level of ``traj`` (empty: a file without levels)."""
    if not traj.levels or traj.level_error.shape[0] != traj.n_steps:
        return []
    ok = traj.success
    kept = traj.level_error[ok]
    relaxed = traj.status[ok] == "relaxed"
    found = []
    for k, name in enumerate(traj.levels):
        column = kept[:, k]
        missed = column > KEPT
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
                int(np.sum(missed & relaxed)),
                float(column.max(initial=0.0)),
                *worst,
                int(np.sum(missed & ~relaxed)),
            )
        )
    return found
