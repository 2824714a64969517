"""A run's step laid out: its spec's parts packed into the compiled pipeline's arrays.

:func:`build` walks a :class:`~dvqp.resolution.StepSpec` once: dvqp's own parts (identified by
their exact class) become rows of the pipeline's tables (:mod:`dvqp.step.arrays`); a part of
your own (any other class, including a subclass of one of dvqp's) becomes a hook, called by the
step between the compiled stages (:mod:`dvqp.step.hooks`). The obstacles of every part and of
the recording are measured once per state, as one union (each part reads its own rows).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import ArrayLike

from dvqp.errors import ParameterError
from dvqp.geometry.measure import OTHER, ShapeArrays
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits import AccelerationLimit, ObstacleDamper, SelfCollision, TiltLimit
from dvqp.limits.damper import DamperArrays, VelocityDamper
from dvqp.limits.height import ProbeHeight, SurfaceHeight
from dvqp.limits.joints import JointPositionLimit, JointVelocityLimit
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel
from dvqp.objective.term import per_point
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver
from dvqp.step.arrays import (
    BoundArrays,
    MeasureArrays,
    ObjectiveArrays,
    PinvArrays,
    Pipeline,
    RecordArrays,
)
from dvqp.step.hooks import Hooks
from dvqp.tasks import ToolTask
from dvqp.workspace import StepPlan

DAMPERS = (ObstacleDamper, SurfaceHeight, ProbeHeight, TiltLimit, SelfCollision)
BOUNDS = (JointPositionLimit, JointVelocityLimit, AccelerationLimit)


@dataclass(frozen=True)
class Block:
    """Verified values ``[start, stop)`` of one limit, for reports: what each value is."""

    limit: object
    start: int
    stop: int
    labels: tuple[str, ...]


@dataclass
class Layout:
    """What :func:`build` makes of a spec (the pipeline is assembled from it by the engine)."""

    plan: StepPlan
    shapes: tuple[Shape, ...]
    objective: ObjectiveArrays
    bounds: BoundArrays
    measures: MeasureArrays
    params: DamperArrays
    hooks: Hooks
    blocks: list[Block] = field(default_factory=list)
    joint_values: int = -1
    damper_values: int = -1


class _Union:
    """Shapes of several obstacle sets, each once; a set's rows in the union."""

    def __init__(self, sets: Sequence[ObstacleSet]) -> None:
        self.shapes: list[Shape] = list({id(s): s for shapes in sets for s in shapes}.values())
        self.rows = {id(shape): row for row, shape in enumerate(self.shapes)}

    def members(self, shapes: ObstacleSet) -> np.ndarray:
        return np.array([self.rows[id(s)] for s in shapes], dtype=np.int64)


def build(
    robot: Robot, radius: float, spec: StepSpec, recorded: ObstacleSet, q0: np.ndarray, dt: float
) -> tuple[Layout, np.ndarray]:
    """The layout of ``spec``'s step on ``robot`` in a pipe of ``radius`` (m), and the rows of
    the ``recorded`` obstacles in its union; parts of your own are sized at ``q0`` (rad) with
    the step ``dt`` (s)."""
    terms, limits = spec.objective.terms, spec.limits
    sets = [t.obstacles for t in terms if type(t) in (ObstaclePoints, ObstacleLinks)]
    sets += [d.obstacles for d in limits if type(d) is ObstacleDamper]
    union = _Union([*sets, recorded])
    n, k = robot.n, robot.n_points
    plan = StepPlan(n, k, radius, len(union.shapes), robot.has_rail)
    state = KinematicState.compute(robot, q0, radius)
    hooks = Hooks(plan, state, dt)
    table: dict[str, list] = {key: [] for key in MeasureArrays.__dataclass_fields__}
    table["obstacle_offsets"].append(0)
    for task in spec.tasks:
        if type(task) is ToolTask:
            table["tool_rows"].append(plan.task_rows(4)[0].start)
        else:
            hooks.task(task)
    objective = _objective(spec, union, n, k, hooks)
    params, blocks = _dampers(limits, union, plan, hooks, table)
    for limit in limits:
        if type(limit) not in BOUNDS and not isinstance(limit, VelocityDamper):
            hooks.limit(limit)
    measures = MeasureArrays(**{key: np.array(rows, dtype=np.int64) for key, rows in table.items()})
    measures = replace(
        measures, heights=measures.heights.reshape(-1, 3), chords=measures.chords.reshape(-1, 2)
    )
    layout = Layout(
        plan, tuple(union.shapes), objective, _bounds(limits, n), measures, params, hooks
    )
    _verified(layout, limits, blocks, n)
    return layout, union.members(recorded)


def _objective(spec: StepSpec, union: _Union, n: int, k: int, hooks: Hooks) -> ObjectiveArrays:
    """dvqp's terms as tables; a user's terms as hooks."""
    levels, gains = [], []
    point_coef, link_coef = np.zeros((len(union.shapes), k)), np.zeros((len(union.shapes), k - 1))
    for term in spec.objective.terms:
        kind = type(term)
        if kind is OrbitalLevel:
            levels.append(term.level)  # type: ignore[attr-defined]
            gains.append(per_point("k_height", term.k_height, k))  # type: ignore[attr-defined]
        elif kind in (ObstaclePoints, ObstacleLinks):
            k1 = per_point("k_obstacle", term.k_obstacle, k)  # type: ignore[attr-defined]
            rows = union.members(term.obstacles)  # type: ignore[attr-defined]
            coef = term.obstacles.weights[:, None] * k1[None, :]  # type: ignore[attr-defined]
            if kind is ObstaclePoints:
                point_coef[rows] += coef
            else:
                link_coef[rows] += coef[:, :-1]
        else:
            hooks.term(term)
    return ObjectiveArrays(
        np.array(levels, dtype=float),
        np.array(gains).reshape(-1, k),
        point_coef,
        link_coef,
        np.zeros((k, 2)),
        hooks.plan.objective_value,
        hooks.plan.objective_gradient,
        float(spec.objective.gain),
    )


def _bounds(limits: Sequence[object], n: int) -> BoundArrays:
    """The joint limits' boxes: position and velocity intersected, at most one acceleration."""
    q_min, q_max, qd_max = np.full(n, -math.inf), np.full(n, math.inf), np.full(n, math.inf)
    accel = None
    for limit in limits:
        if type(limit) is JointPositionLimit:
            q_min, q_max = np.maximum(q_min, limit.q_min), np.minimum(q_max, limit.q_max)
        elif type(limit) is JointVelocityLimit:
            qd_max = np.minimum(qd_max, limit.qd_max)
        elif type(limit) is AccelerationLimit:
            accel = limit
    if accel is None:
        return BoundArrays(
            q_min, q_max, qd_max, False, np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
        )
    return BoundArrays(
        q_min,
        q_max,
        qd_max,
        True,
        np.array(accel.qdd_max),
        np.array(accel.q_min),
        np.array(accel.q_max),
        accel.previous,
    )


def _dampers(
    limits: Sequence[object], union: _Union, plan: StepPlan, hooks: Hooks, table: dict[str, list]
) -> tuple[DamperArrays, list[tuple]]:
    """Every damper's rows: dvqp's measured by the pipeline (into ``table``, the fields of
    :class:`~dvqp.step.arrays.MeasureArrays`), a user's by a hook."""
    params: list[tuple[float, ...]] = []
    blocks: list[tuple] = []
    for limit in limits:
        if not isinstance(limit, VelocityDamper) or (
            type(limit) is TiltLimit and limit.min_tilt == 0.0
        ):
            continue
        if type(limit) in DAMPERS:
            start, count = _measured(limit, union, plan, table)
            safe, labels = limit.safe, limit.labels(plan.k, plan.rail)
        else:
            start, count, safe, labels = hooks.damper(limit)
        if count == 0:
            continue
        row = (
            limit.gain,
            limit.tolerance,
            limit.deceleration,
            float(limit.reach),
            float(type(limit) is TiltLimit),
        )
        params += [(float(s), *row) for s in np.broadcast_to(np.asarray(safe, float), (count,))]
        blocks.append((limit, start, count, labels))
    columns = np.array(params, dtype=float).reshape(-1, 6).T.copy()
    arrays = DamperArrays(*(np.ascontiguousarray(c) for c in columns[:5]), columns[5] != 0.0)
    return arrays, blocks


def _measured(
    limit: object, union: _Union, plan: StepPlan, table: dict[str, list]
) -> tuple[int, int]:
    """Rows of one of dvqp's dampers: ``(first row, count)``, its instance recorded."""
    k, kind, members = plan.k, type(limit), []
    # heights: (points, link chords): the body points, links and carriage; the probe, holder
    points, chords = {
        SurfaceHeight: (k, [*range(k - 1), *([k] if plan.rail else [])]),
        ProbeHeight: (1, [k - 1]),
    }.get(kind, (0, []))
    if kind is ObstacleDamper:
        members = union.members(limit.obstacles).tolist()
        count = len(members) * (2 * k + 1 + 2 * plan.rail)
    else:
        count = points + len(chords) or {TiltLimit: 1, SelfCollision: plan.pairs.i.shape[0]}[kind]
    if count == 0:
        return 0, 0
    start = plan.damper_rows(count)[0].start
    if kind is ObstacleDamper:
        table["obstacle_start"].append(start)
        table["obstacle_members"].extend(members)
        table["obstacle_offsets"].append(len(table["obstacle_members"]))
    elif points:
        table["heights"].append((start, 0 if kind is SurfaceHeight else k, points))
        table["chords"].extend((start + points + c, link) for c, link in enumerate(chords))
    else:
        table["tilts" if kind is TiltLimit else "selves"].append(start)
    return start, count


def _verified(layout: Layout, limits: Sequence[object], dampers: list[tuple], n: int) -> None:
    """The verified values: the joint room (if a position limit), then every damper row."""
    plan = layout.plan
    if any(type(limit) is JointPositionLimit for limit in limits):
        slot = plan.verified(2 * n, 0.0, JointPositionLimit.tolerance)
        layout.joint_values = slot.start
        names = tuple(f"joint{i + 1}" for i in range(n))
        layout.blocks.append(Block(JointPositionLimit, slot.start, slot.stop, names + names))
    if not dampers:
        return
    p = layout.params
    safe = np.where(p.angle, np.arcsin(np.minimum(p.safe, 1.0)), p.safe)
    slot = plan.verified(p.safe.shape[0], safe, p.depth)
    layout.damper_values = slot.start
    for limit, start, count, labels in dampers:
        first = slot.start + start
        named = (*labels, *(f"{limit.name}{i + 1}" for i in range(len(labels), count)))
        layout.blocks.append(Block(limit, first, first + count, named[:count]))


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
    baseline = isinstance(resolver, PseudoinverseResolver)
    damping = resolver.damping if isinstance(resolver, PseudoinverseResolver) else 0.0
    if damping > 0.0 and layout.hooks.soft:
        raise ParameterError("damping", "the damped inverse takes no soft tasks")
    shapes = ShapeArrays.of(layout.shapes, plan.period)
    m = layout.measures  # each obstacle's links measured to the last precision below its margin
    dampers = [d for d in spec.limits if type(d) is ObstacleDamper and len(d.obstacles)]
    shapes.refine[:] = 0.0
    far = np.zeros(len(layout.shapes))  # the broad phase: exact rows up to every damper's reach
    for o, damper in enumerate(dampers):
        rows = m.obstacle_members[m.obstacle_offsets[o] : m.obstacle_offsets[o + 1]]
        shapes.refine[rows] = np.maximum(shapes.refine[rows], damper.safe)
        far[rows] = np.maximum(far[rows], damper.reach)
    if not layout.hooks.active:  # parts of your own may read any row: every row exact
        boxed = shapes.code != OTHER
        shapes.far[boxed] = far[boxed]
    layout.hooks.finalize(layout.shapes, shapes.code, layout.params, layout.damper_values)
    fields = [f for f in RecordArrays.__dataclass_fields__ if f != "index"]
    record = (
        RecordArrays.none(n, k)
        if samples is None
        else RecordArrays(np.full(1, -1, np.int64), *(samples[f] for f in fields))
    )
    x = np.zeros(n)  # the step: the baseline's is written there directly
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
        layout.params,
        plan.dampers,
        plan.qp,
        PinvArrays(baseline, weights, layout.hooks.soft, damping, np.zeros(2), x),
        plan.checks,
        layout.joint_values,
        layout.damper_values,
        rows,
        np.zeros(7),
        record,
    )
