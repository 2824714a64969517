"""One verified step: resolve, integrate, check every limit exactly, split the step if needed.

The QP holds its limits linearised one step ahead. :func:`advance` integrates the answer,
evaluates every verified limit exactly at the configuration reached (the compiled conclusion of
:class:`~dvqp.step.engine.Stepper`) — at its end and, for a large step, at interior points of
the straight motion — and if one is broken by more than its tolerance, solves the step again
as two half steps, each verified the same way, up to ``max_halvings`` times (at most
``2**max_halvings`` substeps). A split step is saved as its mean velocity, so the straight
motion from its start to its end, which is what the trajectory holds and the arm executes, is
verified too, and the acceleration limit continues from that mean. If a step still breaks a
limit, it fails, names the limit, the part and the amount, and the arm holds still.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp.limits import NO_EXCESS, Excess
from dvqp.resolution.step import Step
from dvqp.step.engine import Made, Stepper

MAX_HALVINGS = 5
"""A step is split into at most 2⁵ = 32 substeps before it is declared failed."""

JOINT_STRIDE = 0.02
"""rad: the straight motion of a step is also checked at interior points this far apart."""

STATUS_RANK = ("optimal", "slowed")
"""A split step's status is its substeps' worst: optimal, slowed, else relaxed."""

SINGULAR = Excess(math.inf, 1.0, "singular configuration", "a guarded frame on the pipe axis")


class Advance(NamedTuple):
    """What one step of ``dt`` did (the stepper then holds the state it ended in): the combined
    ``step`` (``qdot`` the mean joint velocity over ``dt``, ``task_error`` the largest of the
    substeps', ``solve_time`` and ``iterations`` their sums), its ``substeps`` (1 if not split)
    and the ``excess`` that broke a failed step (:data:`~dvqp.limits.NO_EXCESS` otherwise)."""

    step: Step
    substeps: int
    excess: Excess = NO_EXCESS


def advance(
    stepper: Stepper,
    command: NDArray[np.float64],
    dt: float,
    *,
    verify: bool = True,
    max_halvings: int = MAX_HALVINGS,
    record: int = -1,
    made: Made | None = None,
) -> Advance:
    """Resolve and integrate one step of ``dt`` seconds from the stepper's loaded state.

    Parameters
    ----------
    stepper
        The run's step, loaded with the state the step starts from.
    command
        The tool's DV velocity command, shape (4,).
    dt
        Step, s.
    verify
        Split and fail steps that break a limit (a resolver that holds no limits, like the
        baseline, is only measured: ``verify=False``).
    max_halvings
        Most times a step is halved, >= 0.
    record
        The trajectory sample the state reached is written to (−1: none).
    made
        The step's compiled call, already made for ``command`` and ``dt`` by a run's compiled
        loop (:func:`dvqp.motion.follow.follow`) from ``made.start``, loaded then: the step
        goes on from its values.
    """
    start = stepper.state.q.copy() if made is None else made.start
    stepper.record_at[0] = record
    moved = _attempt(stepper, start, command, dt, 0, verify, max_halvings, made)
    if moved.substeps > 1 and moved.step.success:
        end = stepper.state.q.copy()
        stepper.record_at[0] = -1
        broken = straight_excess(stepper, start, end)
        if verify and broken.broken:
            stepper.observe(np.zeros_like(start), dt)
            moved = _failed(moved.step, broken, moved.substeps, "the straight motion: ")
        else:
            stepper.observe(moved.step.qdot, dt)
            start = end
    if moved.substeps > 1 or not moved.step.success or stepper.record_at[0] != record:
        stepper.record_at[0] = record  # the sample: the state the step ended in
        stepper.load(start)
    return moved


def _attempt(
    stepper: Stepper,
    q: NDArray[np.float64],
    command: NDArray[np.float64],
    dt: float,
    depth: int,
    verify: bool,
    halvings: int,
    made: Made | None = None,
) -> Advance:
    """A step of ``dt`` from ``q`` (loaded, or ``made``'s), halved while it breaks a limit."""
    found, reached = stepper.resolve_and_move(command, dt, made)
    if not found.success:
        stepper.observe(np.zeros_like(q), dt)
        failed = Step(
            np.zeros_like(q),
            False,
            found.status,
            math.inf,
            found.solve_time,
            found.iterations,
            found.solver_time,
            0.0,
        )
        return Advance(failed, 1)
    if reached is None:  # not made with it
        reached = stepper.move()
    motion, levels = stepper.motion, stepper.level_error
    step = Step(
        stepper.x.copy(),
        True,
        found.status,
        float(motion[0]),
        found.solve_time,
        found.iterations,
        found.solver_time,
        found.rate,
        levels.copy() if levels.shape[0] > 1 else None,
    )
    broken = _excess(stepper, q, verify) if reached else SINGULAR
    if not reached and (not verify or depth >= halvings):
        raise stepper.singular()
    if not verify or not broken.broken:
        stepper.observe(step.qdot, dt)
        return Advance(step, 1)
    if depth >= halvings:
        stepper.observe(np.zeros_like(q), dt)
        return _failed(step, broken, 2**depth)
    record = int(stepper.record_at[0])
    stepper.record_at[0] = -1
    stepper.load(q)
    first = _attempt(stepper, q, command, 0.5 * dt, depth + 1, verify, halvings)
    if not first.step.success:
        return first
    middle = stepper.state.q.copy()
    second = _attempt(stepper, middle, command, 0.5 * dt, depth + 1, verify, halvings)
    stepper.record_at[0] = record
    if not second.step.success:
        return Advance(second.step, first.substeps + second.substeps, second.excess)
    return _joined(q, stepper.state.q, first, second, dt)


def _excess(stepper: Stepper, q: NDArray[np.float64], verify: bool) -> Excess:
    """What the step just integrated from ``q`` breaks (if ``verify``): at its end, else, for a
    large step, at interior points of its straight motion (the end is loaded again after)."""
    if verify and stepper.broken:
        return stepper.excess()
    if not verify or stepper.motion[1] <= JOINT_STRIDE:
        return NO_EXCESS
    record, end = int(stepper.record_at[0]), stepper.state.q.copy()
    stepper.record_at[0] = -1
    broken = straight_excess(stepper, q, end)
    stepper.record_at[0] = record
    stepper.load(end)
    return broken


def straight_excess(stepper: Stepper, q: NDArray[np.float64], end: NDArray[np.float64]) -> Excess:
    """What the straight motion from ``q`` to ``end`` breaks at interior points spaced at most
    :data:`JOINT_STRIDE` rad apart in every joint (none for a small step: there the deviation
    of the limits from their linearisation is far below their tolerances): the worst excess if
    one is broken, else :data:`~dvqp.limits.NO_EXCESS`."""
    delta = end - q
    count = math.ceil(float(np.abs(delta).max()) / JOINT_STRIDE) - 1
    worst, ratio = None, 1.0
    for a in np.linspace(0.0, 1.0, count + 2)[1:-1] if count > 0 else ():
        if not stepper.load(q + a * delta):
            return SINGULAR
        found = float(stepper.excess_now[1])
        if found > ratio or found != found:
            worst, ratio = a, found
    if worst is None:
        return NO_EXCESS
    stepper.load(q + worst * delta)
    return stepper.excess()


def _failed(step: Step, broken: Excess, substeps: int, where: str = "") -> Advance:
    status = f"failed: {where}{broken.describe()} in {substeps} substeps"
    levels = None if step.level_error is None else np.full_like(step.level_error, math.inf)
    failed = Step(
        np.zeros_like(step.qdot),
        False,
        status,
        math.inf,
        step.solve_time,
        step.iterations,
        step.solver_time,
        0.0,
        levels,
    )
    return Advance(failed, substeps, broken)


def _joined(
    q: NDArray[np.float64], end: NDArray[np.float64], first: Advance, second: Advance, dt: float
) -> Advance:
    a, b = first.step, second.step
    both = {a.status, b.status}
    status = "relaxed" if both - set(STATUS_RANK) else max(both, key=STATUS_RANK.index)
    counted = a.iterations is not None and b.iterations is not None
    iterations = a.iterations + b.iterations if counted else None  # type: ignore[operator]
    step = Step(
        (end - q) / dt,
        True,
        status,
        max(a.task_error, b.task_error),
        a.solve_time + b.solve_time,
        iterations,
        a.solver_time + b.solver_time,
        0.5 * (a.rate + b.rate),
        None if a.level_error is None else np.maximum(a.level_error, b.level_error),
    )
    return Advance(step, first.substeps + second.substeps)
