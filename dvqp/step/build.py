"""A run's step laid out: its spec's parts, each joined to the compiled pipeline's arrays.

:func:`build` asks every part of a :class:`~dvqp.resolution.StepSpec` (its tasks, objective
terms and limits, in order) to join the step (``part.join(step)``, see
:mod:`dvqp.workspace.wiring`): dvqp's parts write themselves into the pipeline's tables
(:mod:`dvqp.step.arrays`), a part of your own hands itself to the hooks called by the step
between the compiled stages (:mod:`dvqp.step.hooks`). Nothing here tests what a part is. The
obstacles the parts and the recording measure are measured once per state, as one union (each
part reads its own rows).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike

from dvqp.errors import ParameterError
from dvqp.geometry.measure import ShapeArrays
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DamperArrays
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver
from dvqp.step.arrays import (
    BoundArrays,
    MeasureArrays,
    ObjectiveArrays,
    PinvArrays,
    Pipeline,
    RecordArrays,
    TaskArrays,
)
from dvqp.step.hooks import Hooks
from dvqp.workspace import StepPlan
from dvqp.workspace.wiring import StepWiring


@dataclass(frozen=True)
class Block:
    """Verified values ``[start, stop)`` of one limit, for reports: what each value is;
    ``damper``: damper rows (else the joints' room)."""

    limit: object
    start: int
    stop: int
    labels: tuple[str, ...]
    damper: bool = True


@dataclass
class Layout:
    """What :func:`build` makes of a spec (the pipeline is assembled from it by the engine)."""

    plan: StepPlan
    shapes: tuple[Shape, ...]
    objective: ObjectiveArrays
    bounds: BoundArrays
    measures: MeasureArrays
    tasks: TaskArrays
    row_weights: np.ndarray
    params: DamperArrays
    hooks: Hooks
    refine: np.ndarray
    far: np.ndarray
    blocks: list[Block] = field(default_factory=list)
    joint_values: int = -1
    damper_values: int = -1


def build(
    robot: Robot, radius: float, spec: StepSpec, recorded: ObstacleSet, q0: np.ndarray, dt: float
) -> tuple[Layout, np.ndarray]:
    """The layout of ``spec``'s step on ``robot`` in a pipe of ``radius`` (m), and the rows of
    the ``recorded`` obstacles in its union; parts of your own are sized at ``q0`` (rad) with
    the step ``dt`` (s)."""
    parts = (*spec.tasks, *spec.objective.terms, *spec.limits)
    union = [*(shape for part in parts for shape in part.measured), *recorded]
    n, k = robot.n, robot.n_points
    shapes = len({id(shape) for shape in union})
    plan = StepPlan(n, k, radius, shapes, robot.has_rail, robot.part_names)
    hooks = Hooks(plan, KinematicState.compute(robot, q0, radius), dt)
    step = StepWiring(plan, hooks, union, hooks.start)
    weights: list[float] = []
    breaks, priority = [0], None
    for task in spec.tasks:  # in order of priority: each level's rows follow each other
        before = plan.rows("tasks")
        task.join(step)
        count = plan.rows("tasks") - before
        if task.hard and priority is not None and task.priority != priority:
            breaks.append(before)
        priority = task.priority if task.hard else priority
        weights += [float(task.weight)] * count
    breaks.append(plan.rows("tasks"))
    for part in parts[len(spec.tasks) :]:
        part.join(step)
    table = {key: np.array(rows, dtype=np.int64) for key, rows in step.measures.items()}
    measures = replace(
        MeasureArrays(**table),
        heights=table["heights"].reshape(-1, 3),
        chords=table["chords"].reshape(-1, 2),
    )
    objective = ObjectiveArrays(
        np.array(step.levels, dtype=float),
        np.array(step.k_height).reshape(-1, k),
        *step.coefficients(),
        np.zeros((k, 3)),
        plan.objective_value,
        plan.objective_gradient,
        float(spec.objective.gain),
    )
    columns = step.damper_parameters()
    params = DamperArrays(*(np.ascontiguousarray(c) for c in columns[:5]), columns[5] != 0.0)
    refine, far = step.refinement(len(step.shapes))
    layout = Layout(
        plan,
        tuple(step.shapes),
        objective,
        _bounds(step),
        measures,
        _tasks(step, np.array(breaks, dtype=np.int64)),
        np.array(weights),
        params,
        hooks,
        refine,
        far,
    )
    _verified(layout, step, robot.joint_names)
    return layout, step.rows_of(recorded)


def _tasks(step: StepWiring, levels: np.ndarray) -> TaskArrays:
    """The compiled tasks' tables and the levels' first rows (``levels`` (L + 1,))."""
    n, t = step.plan.n, step.tasks
    points, postures = t["point"], t["posture"]
    return TaskArrays(
        np.array(t["tool"], dtype=np.int64).reshape(-1, 6),
        np.array([entry for entry, _, _ in points], dtype=np.int64).reshape(-1, 6),
        np.array([target for _, target, _ in points], dtype=float).reshape(-1, 3),
        np.array([gain for _, _, gain in points], dtype=float),
        np.array([first for first, _, _ in postures], dtype=np.int64),
        np.array([target for _, target, _ in postures], dtype=float).reshape(-1, n),
        np.array([gain for _, _, gain in postures], dtype=float),
        levels,
        np.zeros(levels.shape[0] - 1),
    )


def _bounds(step: StepWiring) -> BoundArrays:
    """The joint limits' boxes: position and velocity intersected, at most one acceleration."""
    accel, n = step.acceleration, step.plan.n
    if accel is None:
        zero = np.zeros(n)
        return BoundArrays(
            step.q_min, step.q_max, step.qd_max, False, zero, zero.copy(), zero.copy(), zero.copy()
        )
    return BoundArrays(
        step.q_min,
        step.q_max,
        step.qd_max,
        True,
        np.array(accel.qdd_max),
        np.array(accel.q_min),
        np.array(accel.q_max),
        accel.previous,
    )


def _verified(layout: Layout, step: StepWiring, joints: tuple[str, ...]) -> None:
    """The verified values: the joint room (if a position limit, labelled by the ``joints``'
    names), then every damper row."""
    plan, n = layout.plan, step.plan.n
    if step.joint_limit is not None:
        slot = plan.verified(2 * n, 0.0, step.joint_limit.tolerance)
        layout.joint_values = slot.start
        layout.blocks.append(
            Block(step.joint_limit, slot.start, slot.stop, joints + joints, damper=False)
        )
    if not step.dampers:
        return
    p = layout.params
    safe = np.where(p.angle, np.arcsin(np.minimum(p.safe, 1.0)), p.safe)
    slot = plan.verified(p.safe.shape[0], safe, p.depth)
    layout.damper_values = slot.start
    for block in step.dampers:
        first, count = slot.start + block.start, block.count
        more = (f"{block.limit.name}{i + 1}" for i in range(len(block.labels), count))
        named = (*block.labels, *more)
        layout.blocks.append(Block(block.limit, first, first + count, named[:count]))


def _pinv_arrays(
    resolver: Resolver, weights: np.ndarray, rows: np.ndarray, soft: bool, x: np.ndarray
) -> PinvArrays:
    """The baseline's arrays (for a QP resolver: unused), ``rows`` (m,) the task rows'
    weights, ``x`` (n,) its step.

    Raises
    ------
    ParameterError
        A damped inverse with soft tasks (``soft``).
    """
    damping = resolver.baseline_damping()
    baseline = damping is not None
    damping = 0.0 if damping is None else damping
    if damping > 0.0 and soft:
        raise ParameterError("damping", "the damped inverse takes no soft tasks")
    return PinvArrays(baseline, weights, rows, soft, damping, np.zeros(3), x)


def lay_out(
    robot: Robot,
    radius: float,
    resolver: Resolver,
    q0: ArrayLike,
    dt: float,
    obstacles: ObstacleSet | None,
    samples: Mapping[str, np.ndarray] | None,
) -> tuple[Layout, Pipeline]:
    """The layout of ``resolver``'s step and every array of its pipeline (see
    :class:`~dvqp.step.engine.Stepper` for the parameters)."""
    spec, n, k = resolver.spec, robot.n, robot.n_points
    recorded = ObstacleSet() if obstacles is None else obstacles
    layout, rows = build(robot, radius, spec, recorded, robot.check_q(q0, "q0"), dt)
    plan = layout.plan
    plan.finalize()
    assert plan.qp is not None and plan.dampers is not None and plan.checks is not None
    weights = spec.diagonal(n)
    plan.qp.P[:] = np.diag(weights)
    x = np.zeros(n)  # the step: the baseline's is written there directly
    pinv = _pinv_arrays(resolver, weights, layout.row_weights, layout.hooks.soft, x)
    shapes = ShapeArrays.of(layout.shapes, plan.period)
    shapes.refine[:] = layout.refine  # links measured to the last precision below a margin
    if not layout.hooks.active:  # parts of your own may read any row: every row exact
        compiled = shapes.compiled  # the broad phase: exact rows up to every damper's reach
        shapes.far[compiled] = layout.far[compiled]
    layout.hooks.finalize(layout.shapes, shapes.compiled, layout.params, layout.damper_values)
    fields = [f for f in RecordArrays.__dataclass_fields__ if f != "index"]
    record = (
        RecordArrays.none(n, k)
        if samples is None
        else RecordArrays(np.full(1, -1, np.int64), *(samples[f] for f in fields))
    )
    return layout, Pipeline(
        float(radius),
        plan.dt,
        plan.command,
        x,
        np.zeros(2),
        robot.model_arrays(),
        plan.state,
        shapes,
        plan.proximity,
        plan.pairs,
        layout.objective,
        layout.bounds,
        layout.measures,
        layout.tasks,
        layout.params,
        plan.dampers,
        plan.qp,
        pinv,
        plan.checks,
        layout.joint_values,
        layout.damper_values,
        plan.names.base_link,
        rows,
        np.zeros(7),
        record,
    )
