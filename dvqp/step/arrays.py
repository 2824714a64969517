"""Every array a run's compiled step reads and writes, grouped as the stages use them.

:class:`Pipeline` is packed once per run into one numba struct
(:func:`dvqp.workspace.as_struct`) and handed to the compiled stages
(:mod:`dvqp.step.stages`). Its layout is the same for every run: a part kind a run lacks has
arrays of size 0, so the stages compile once and are loaded from numba's cache afterwards.
Sizes: n joints, k body points, J obstacles, D damper rows, V verified values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.geometry.measure import ShapeArrays
from dvqp.kinematics.model import ModelArrays
from dvqp.limits.damper import DamperArrays
from dvqp.workspace.buffers import PairBuffers, ProximityBuffers, StateBuffers
from dvqp.workspace.plan import CheckBuffers, DamperBuffers, QPBuffers

Array = NDArray[np.float64]
Index = NDArray[np.int64]


@dataclass(frozen=True)
class ObjectiveArrays:
    """dvqp's objective terms of a run, and ``w``, ``∂w/∂Q`` of the current state: each
    :class:`~dvqp.objective.OrbitalLevel`'s ``h*`` (``levels`` (T,), m) and ``k²``
    (``k_height`` (T, k), 1/m²); ``Σ w_j k¹_i`` of the obstacle-point and obstacle-link terms
    (``point_coef`` (J, k), ``link_coef`` (J, k − 1); 0 where none sees j); ``scratch`` (k, 3);
    ``w`` and ``∂w/∂Q`` (``value`` (1,), ``gradient`` (n,)); ``gain`` λ."""

    levels: Array
    k_height: Array
    point_coef: Array
    link_coef: Array
    scratch: Array
    value: Array
    gradient: Array
    gain: float


@dataclass(frozen=True)
class BoundArrays:
    """The joint limits' boxes: position ``q_min``, ``q_max`` (rad; ±inf without), velocity
    ``qd_max`` (rad/s; inf without) and, if ``accelerate``, the acceleration limit's ``qdd_max``
    (rad/s²), its own ``q_min``, ``q_max`` and its live ``previous`` velocity (n,) each."""

    q_min: Array
    q_max: Array
    qd_max: Array
    accelerate: bool
    qdd_max: Array
    accel_q_min: Array
    accel_q_max: Array
    previous: Array


@dataclass(frozen=True)
class TaskArrays:
    """dvqp's compiled tasks and the levels of the task rows ``A Q̇ = b`` (m rows, L levels).

    ``tool`` (T, 6): each :class:`~dvqp.tasks.ToolTask`'s ``[first row, count, c0 .. c3]``
    (rows of ``J̄``, −1 unused); ``point`` (P, 6): each :class:`~dvqp.tasks.PointTask`'s
    ``[first row, count, point, c0 .. c2]``, its ``point_target`` (P, 3) (m) and
    ``point_gain`` (P,) (1/s); ``posture`` (Q,): each :class:`~dvqp.tasks.PostureTask`'s first
    row, its ``posture_target`` (Q, n) (rad) and ``posture_gain`` (Q,); ``levels`` (L + 1,)
    the first row of each level and m; ``level_error`` (L,) each level's ``‖A Q̇ − b‖∞`` of the
    last integrated step (task units per s)."""

    tool: Index
    point: Index
    point_target: Array
    point_gain: Array
    posture: Index
    posture_target: Array
    posture_gain: Array
    levels: Index
    level_error: Array


@dataclass(frozen=True)
class MeasureArrays:
    """Which compiled dampers measure which damper rows (int64): each obstacle damper's first row
    (``obstacle_start`` (O,)) and obstacles ``members[offsets[o]:offsets[o+1]]``
    (``obstacle_members`` (M,), ``obstacle_offsets`` (O + 1,)); ``[first row, first guarded
    point, count]`` of each height damper (``heights`` (H, 3)) and ``[row, link]`` of each of
    their link chords (``chords`` (C, 2)); the first row of each tilt and self-collision damper
    (``tilts``, ``selves``)."""

    obstacle_start: Index
    obstacle_offsets: Index
    obstacle_members: Index
    heights: Index
    chords: Index
    tilts: Index
    selves: Index


@dataclass(frozen=True)
class PinvArrays:
    """The baseline's step (eq. 18), when ``baseline``: ``weights`` (n,) of ``W``, ``rows``
    (m,) the task rows' weights within their level (a level met in least squares weighs its
    rows so), ``dense`` (soft tasks make the metric ``P``), ``damping`` μ, ``info`` (3,) the
    Cholesky pivots' extremes and the level a failure names, ``x`` (n,) the step."""

    baseline: bool
    weights: Array
    rows: Array
    dense: bool
    damping: float
    info: Array
    x: Array


@dataclass(frozen=True)
class RecordArrays:
    """Where the conclusion of a state is written as a trajectory sample: row ``index[0]``
    (none when −1) of the recorder's per-sample arrays."""

    index: Index
    q: Array
    tool: Array
    points: Array
    w: Array
    limit_excess: Array
    limits_kept: NDArray[np.bool_]
    tilt: Array
    self_distance: Array
    min_clearance: Array
    probe_clearance: Array
    link_height: Array
    holder_height: Array
    rail: Array

    @classmethod
    def none(cls, n: int, k: int) -> RecordArrays:
        """Nothing recorded."""
        z = np.zeros(0)
        return cls(
            np.full(1, -1, np.int64),
            np.zeros((0, n)),
            np.zeros((0, 4)),
            np.zeros((0, k, 3)),
            z,
            z.copy(),
            np.zeros(0, np.bool_),
            *(z.copy() for _ in range(6)),
            np.zeros((0, 3)),
        )


@dataclass(frozen=True)
class Pipeline:
    """What the compiled stages read and write (see the module docstring).

    ``dt`` (1,) and ``command`` (4,) are this step's, ``x`` (n,) the joint velocity it
    integrates, ``motion`` (2,) the integrated step's ``[‖A x − b‖∞, largest joint motion]``;
    ``joint_values`` and ``damper_values`` where the joint room and the damper rows start
    among the verified values (−1: none); ``base_link`` a standing arm's base link, left out
    of the body's lowest link (−1: none);
    ``diagnostics`` (7,) the state's ``[tilt, self distance, min clearance, probe clearance,
    index of the closest part]`` over the ``recorded`` obstacle rows, and the lowest height of
    the body and carriage links' chords and of the probe holder's.
    """

    radius: float
    dt: Array
    command: Array
    x: Array
    motion: Array
    model: ModelArrays
    state: StateBuffers
    shapes: ShapeArrays
    near: ProximityBuffers
    pairs: PairBuffers
    objective: ObjectiveArrays
    bounds: BoundArrays
    measures: MeasureArrays
    tasks: TaskArrays
    params: DamperArrays
    dampers: DamperBuffers
    qp: QPBuffers
    pinv: PinvArrays
    checks: CheckBuffers
    joint_values: int
    damper_values: int
    base_link: int
    recorded: Index
    diagnostics: Array
    record: RecordArrays
