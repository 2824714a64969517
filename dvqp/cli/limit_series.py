"""The series of a limits page: each limit's true quantity over a run, against its bound.

:func:`limit_series` replays a trajectory's samples through the exact verification of its
scene's step (:class:`~dvqp.step.Stepper`, loaded at each saved ``q``): the curves are the very
values a run's check compares with its bounds (clearances, heights, tilt, self distance, joint
room), with the broad phase off, so that every clearance is measured exactly, also far from its
obstacle. Clearances are grouped per obstacle, heights into body points, link chords, the probe
and its holder, each curve the least over its parts. Joint positions, speeds and accelerations
are fractions of their limits (bound 1), from the trajectory's ``q``, ``qdot`` and ``qddot``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.scenes.scene import Scene
from dvqp.step import Stepper
from dvqp.step.build import Block

Array = NDArray[np.float64]

BOUND_TOLERANCE = 1e-6
"""rad/s: how far past a QP bound (joint speed) an accepted answer may be: the solution
check's primal tolerance. A joint acceleration's is this over ``dt``."""

MARKS = ("slowed", "relaxed", "braking", "split", "failed")
"""The kinds of step a limits page marks (:attr:`LimitPage.marks`)."""


@dataclass(frozen=True)
class Curve:
    """One limit's quantity over a run.

    Attributes
    ----------
    panel : str
        What it is (``"clearance"``, ``"height"``, ``"joint speed"``, ...): curves of one panel
        share a unit.
    label : str
        Which part: ``"obstacles[1]"``, ``"body points"``, ``"joint3"``...
    t, values : ndarray, shape (M,)
        Times (s) and values (``unit``): a sample's (M = N+1) or a step's (M = N).
    bound, tolerance : float
        The limit's bound (the scene's: ``margin``, ``min_height``, ``min_tilt``..., 1 for a
        fraction) and how far past it the run's check accepts a value.
    unit : str
        ``"m"``, ``"rad"`` or ``""`` (a fraction of the limit).
    upper : bool
        The value must stay at or below ``bound`` (a fraction); else at or above it.
    """

    panel: str
    label: str
    t: Array
    values: Array
    bound: float
    tolerance: float
    unit: str
    upper: bool = False

    @property
    def past(self) -> Array:
        """How far each value is past the bound, in ``unit`` (<= 0: on the safe side)."""
        return self.values - self.bound if self.upper else self.bound - self.values


@dataclass(frozen=True)
class LimitPage:
    """Every curve of a run, in panel order, and its marked steps: ``marks[kind]`` the start
    times (s) of the steps of each kind of :data:`MARKS` (``"split"``: into substeps); and, for
    a run with more than one level of hard tasks, each level's error over time (``levels``:
    curves against 0, not limits: a level gives way where the limits or a level above need it).
    """

    curves: tuple[Curve, ...]
    marks: dict[str, Array]
    dt: float
    levels: tuple[Curve, ...] = ()

    @property
    def panels(self) -> list[str]:
        """The panels of the limits, in order."""
        return list(dict.fromkeys(c.panel for c in self.curves))

    @property
    def level_panels(self) -> list[str]:
        """The panels of the levels' errors (lengths, angles), after the limits'."""
        return list(dict.fromkeys(c.panel for c in self.levels))


def limit_series(scene: Scene, traj: Trajectory) -> LimitPage:
    """The curves of ``traj``, a run of ``scene`` (its arm and limits), against their bounds.

    Raises
    ------
    ParameterError
        The trajectory does not fit the scene's arm, or a sample is singular.
    """
    n, radius = scene.robot.n, scene.pipe_radius
    if traj.q.ndim != 2 or traj.q.shape[1] != n or traj.t.shape[0] < 2:
        raise ParameterError("trajectory", f"needs at least 2 samples of the scene's {n} joints")
    if traj.pipe_radius != radius:
        raise ParameterError(
            "trajectory", f"its pipe radius is {traj.pipe_radius:.6g} m, the scene's {radius:.6g} m"
        )
    dt = float(traj.t[1] - traj.t[0])
    stepper = Stepper(scene.robot, radius, PseudoinverseResolver(scene.spec()), traj.q[0], dt)
    stepper.arrays.shapes.far[:] = np.inf  # every row exact: no box bound far from a shape
    stepper.arrays.shapes.refine[:] = np.inf  # every link's real clearance to the last 10 µm
    c = stepper.arrays.checks
    values = np.empty((traj.t.shape[0], c.values.shape[0]))
    for k, q in enumerate(traj.q):
        if not stepper.load(q):
            raise ParameterError("trajectory", f"sample {k} has a guarded frame on the pipe axis")
        values[k] = c.values
    curves = []
    for block in stepper.layout.blocks:
        if not block.damper:  # the joints' room
            room = values[:, block.start : block.stop]
            curves += _positions(traj.t, room, c.tolerance[block.start], scene)
        else:
            curves += _damper(traj.t, values, c.safe, c.tolerance, block, scene)
    curves += _rates(traj, stepper, dt)
    order = ["clearance", "self distance", "height", "tilt"]
    curves.sort(key=lambda c: order.index(c.panel) if c.panel in order else len(order))
    return LimitPage(tuple(curves), _marks(traj), dt, tuple(_levels(traj)))


def _groups(block: Block, scene: Scene) -> list[tuple[str, str, slice | list[int]]]:
    """``(panel, label, rows)`` of a damper's block: its rows grouped into curves, as the
    damper groups them."""
    k, rail = scene.robot.n_points, bool(scene.robot.has_rail)
    return block.limit.series(block.stop - block.start, k, rail)  # type: ignore[attr-defined]


def _damper(
    t: Array, values: Array, safe: Array, tolerance: Array, block: Block, scene: Scene
) -> list[Curve]:
    """A damper's curves: the least of each group's verified values."""
    unit = getattr(block.limit, "unit", "m")
    rows = np.arange(block.start, block.stop)
    curves = []
    for panel, label, group in _groups(block, scene):
        at = rows[group]
        if at.shape[0]:
            curves.append(
                Curve(
                    panel,
                    label,
                    t,
                    values[:, at].min(axis=1),
                    float(safe[at[0]]),
                    float(tolerance[at[0]]),
                    unit,
                )
            )
    return curves


def _positions(t: Array, room: Array, tolerance: float, scene: Scene) -> list[Curve]:
    """Each limited joint's position as a fraction of its half range from the middle: 1 less
    its verified room (``[q_max − q, q − q_min]``, verified to ``tolerance`` rad) over the
    half range."""
    robot, n = scene.robot, scene.robot.n
    half = 0.5 * (robot.q_max - robot.q_min)
    least = np.minimum(room[:, :n], room[:, n:])
    return [
        Curve(
            "joint position",
            robot.joint_names[i],
            t,
            1.0 - least[:, i] / half[i],
            1.0,
            tolerance / half[i],
            "",
            upper=True,
        )
        for i in range(n)
        if np.isfinite(half[i])
    ]


def _rates(traj: Trajectory, stepper: Stepper, dt: float) -> list[Curve]:
    """Joint speeds ``|q̇|`` and accelerations ``|q̈|`` (per step) as fractions of their
    limits (the step's bounds; none where unlimited or not recorded)."""
    bounds, t, curves = stepper.arrays.bounds, traj.t[:-1], []
    joints = stepper.robot.joint_names
    rates = [("joint speed", traj.qdot, bounds.qd_max, BOUND_TOLERANCE)]
    if bounds.accelerate and traj.qddot.shape == traj.qdot.shape:
        rates.append(("joint acceleration", traj.qddot, bounds.qdd_max, BOUND_TOLERANCE / dt))
    for panel, rate, limit, tol in rates:
        curves += [
            Curve(
                panel,
                joints[i],
                t,
                np.abs(rate[:, i]) / limit[i],
                1.0,
                tol / limit[i],
                "",
                upper=True,
            )
            for i in range(rate.shape[1])
            if np.isfinite(limit[i])
        ]
    return curves


LEVEL_PANELS = ("task level error (m)", "task level error (rad)")
"""The panels of a run with more than one level: each level's error over time (its tasks'
:meth:`~dvqp.Task.deviation`), lengths and angles, against 0."""


def _levels(traj: Trajectory) -> list[Curve]:
    """Each level's worst length and angle error at every sample (a run with more than one
    level; none else), bound 0 (kept exactly)."""
    d, measured = traj.level_deviation, traj.level_measured
    if len(traj.levels) < 2 or d.shape[:2] != (traj.t.shape[0], len(traj.levels)):
        return []
    return [
        Curve(panel, f"level {k + 1}: {name}", traj.t, d[:, k, u], 0.0, 0.0, unit, upper=True)
        for u, (panel, unit) in enumerate(zip(LEVEL_PANELS, ("m", "rad"), strict=True))
        for k, name in enumerate(traj.levels)
        if measured[k, u]
    ]


def _marks(traj: Trajectory) -> dict[str, Array]:
    """The start times (s) of the slowed, relaxed, braking, split and failed steps."""
    t, status = traj.t[:-1], traj.status.astype(str)
    split = traj.substeps > 1 if traj.substeps.shape == t.shape else np.zeros(t.shape, bool)
    return {
        "slowed": t[status == "slowed"],
        "relaxed": t[status == "relaxed"],
        "braking": t[status == "braking"],
        "split": t[split],
        "failed": t[~traj.success],
    }
