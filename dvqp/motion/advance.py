"""One verified step: resolve, integrate, check every limit exactly, split the step if needed.

The resolver's QP holds its limits linearised one step ahead. :func:`advance` integrates the
answer, evaluates every limit of the resolver's spec exactly at the configuration reached
(:mod:`dvqp.limits.excess`) — at its end and, for a large step, at interior points of the
straight motion — and if one is broken by more than its tolerance, solves the step again as
two half steps, each verified the same way, up to ``max_halvings`` times (at most
``2**max_halvings`` substeps). A split step is saved as its mean velocity, so the straight
motion from its start to its end, which is what the trajectory holds and the arm executes, is
verified too, and the acceleration limit continues from that mean. If a step still breaks a
limit, it fails, names the limit, the part and the amount, and the arm holds still.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import NO_EXCESS, Excess, worst_excess
from dvqp.resolution.step import Resolver, Step

MAX_HALVINGS = 5
"""A step is split into at most 2⁵ = 32 substeps before it is declared failed."""

JOINT_STRIDE = 0.02
"""rad: the straight motion of a step is also checked at interior points this far apart."""


@dataclass(frozen=True)
class Advance:
    """What one step of ``dt`` did.

    Attributes
    ----------
    state : KinematicState
        Where the step ended (the start state if it failed).
    step : Step
        The combined step: ``qdot`` is the mean joint velocity over ``dt``, ``task_error`` the
        largest of the substeps, ``solve_time`` and ``iterations`` their sums.
    substeps : int
        1 if the step was not split.
    excess : Excess
        The worst exact limit excess where the step ended, against the run's start (of the
        last attempt if the step failed).
    """

    state: KinematicState
    step: Step
    substeps: int
    excess: Excess


@dataclass(frozen=True)
class _Context:
    robot: Robot
    radius: float
    resolver: Resolver
    command: NDArray[np.float64]
    start: KinematicState
    verify: bool
    max_halvings: int


def advance(
    robot: Robot,
    radius: float,
    resolver: Resolver,
    state: KinematicState,
    command: NDArray[np.float64],
    dt: float,
    *,
    start: KinematicState | None = None,
    verify: bool = True,
    max_halvings: int = MAX_HALVINGS,
) -> Advance:
    """Resolve and integrate one step of ``dt`` seconds from ``state``.

    Parameters
    ----------
    robot, radius
        The arm and the pipe radius (m), for the kinematics of the configuration reached.
    resolver
        Its ``spec.limits`` are the limits checked.
    state
        Kinematics at the start of the step.
    command
        The tool's DV velocity command, shape (4,).
    dt
        Step, s.
    start
        The state the run started from: a limit is kept if its quantity stays at or above
        ``min(bound, value at start)`` (default: ``state``).
    verify
        Split and fail steps that break a limit (a resolver that holds no limits, like the
        baseline, is only measured: ``verify=False``).
    max_halvings
        Most times a step is halved, >= 0.
    """
    first = state if start is None else start
    ctx = _Context(robot, radius, resolver, command, first, verify, max_halvings)
    moved = _attempt(ctx, state, dt, 0)
    if moved.substeps == 1 or not moved.step.success:
        return moved
    # A split step is saved (and executed) as its mean velocity: the straight motion from the
    # step's start to its end. Verify that motion, and let the limits that remember motion
    # (acceleration) continue from the velocity that is saved.
    broken = _straight(ctx, state, moved.state.q, dt)
    if ctx.verify and broken.broken:
        _observe(ctx, np.zeros(state.n), dt)
        return _failed(state, moved.step, broken, moved.substeps, "the straight motion: ")
    _observe(ctx, moved.step.qdot, dt)
    return moved


def _observe(ctx: _Context, qdot: NDArray[np.float64], dt: float) -> None:
    """Tell the limits that remember motion (acceleration) the velocity actually applied."""
    for limit in ctx.resolver.spec.limits:
        observe = getattr(limit, "observe", None)
        if observe is not None:
            observe(qdot, dt)


def _attempt(ctx: _Context, state: KinematicState, dt: float, depth: int) -> Advance:
    step = ctx.resolver.resolve(state, ctx.command, dt)
    if not step.success:
        _observe(ctx, np.zeros(state.n), dt)
        return Advance(state, step, 1, NO_EXCESS)
    try:
        after = KinematicState.compute(ctx.robot, state.q + dt * step.qdot, ctx.radius)
    except DvqpError as exc:
        if not ctx.verify or depth >= ctx.max_halvings:
            raise
        broken = Excess(np.inf, 1.0, "singular configuration", str(exc))
    else:
        end = worst_excess(ctx.resolver.spec.limits, ctx.start, after)
        broken = end
        if ctx.verify and not broken.broken:  # decides with the interior points too
            broken = _straight(ctx, state, after.q, dt, broken)
        if not ctx.verify or not broken.broken:
            _observe(ctx, step.qdot, dt)
            return Advance(after, step, 1, end)  # what the sample holds: the end's excess
    if depth >= ctx.max_halvings:
        _observe(ctx, np.zeros(state.n), dt)
        return _failed(state, step, broken, 2**depth)
    first = _attempt(ctx, state, 0.5 * dt, depth + 1)
    if not first.step.success:
        return first
    second = _attempt(ctx, first.state, 0.5 * dt, depth + 1)
    if not second.step.success:
        return Advance(state, second.step, first.substeps + second.substeps, second.excess)
    return _joined(state, first, second, dt)


def _straight(
    ctx: _Context, state: KinematicState, end: NDArray[np.float64], dt: float,
    worst: Excess = NO_EXCESS,
) -> Excess:  # fmt: skip
    """The worst excess at interior points of the straight motion from ``state`` to ``end``.

    The points are spaced at most :data:`JOINT_STRIDE` rad apart in every joint (none for a
    small step: there the deviation of the limits from their linearisation is far below
    their tolerances); ``worst`` is returned if none is worse.
    """
    delta = end - state.q
    count = math.ceil(float(np.abs(delta).max()) / JOINT_STRIDE) - 1
    if count <= 0:  # the usual small step: nothing between its ends to check
        return worst
    for a in np.linspace(0.0, 1.0, count + 2)[1:-1]:
        try:
            inner = KinematicState.compute(ctx.robot, state.q + a * delta, ctx.radius)
        except DvqpError as exc:
            return Excess(np.inf, 1.0, "singular configuration", str(exc))
        found = worst_excess(ctx.resolver.spec.limits, ctx.start, inner)
        if found.ratio > worst.ratio:
            worst = found
    return worst


def _failed(
    state: KinematicState, step: Step, broken: Excess, substeps: int, where: str = ""
) -> Advance:
    status = f"failed: {where}{broken.describe()} in {substeps} substeps"
    failed = Step(np.zeros(state.n), False, status, np.inf, step.solve_time, step.iterations,
                  step.solver_time)  # fmt: skip
    return Advance(state, failed, substeps, broken)


def _joined(start: KinematicState, first: Advance, second: Advance, dt: float) -> Advance:
    a, b = first.step, second.step
    status = "optimal" if a.status == b.status == "optimal" else "relaxed"
    counted = a.iterations is not None and b.iterations is not None
    iterations = a.iterations + b.iterations if counted else None  # type: ignore[operator]
    step = Step(
        qdot=(second.state.q - start.q) / dt,
        success=True,
        status=status,
        task_error=max(a.task_error, b.task_error),
        solve_time=a.solve_time + b.solve_time,
        iterations=iterations,
        solver_time=a.solver_time + b.solver_time,
    )
    return Advance(second.state, step, first.substeps + second.substeps, second.excess)
