"""A run ends at rest: after its last command it brakes until every joint has stopped.

The braking steps are ordinary verified steps (:func:`dvqp.step.advance`) of the run's own step,
with the tool held still (command 0) and the stepper :attr:`~dvqp.step.Stepper.stopping`: every
task's right side and the cost's linear part are 0 (λ = 0, no null-space motion), so the QP
minimises ``½ Q̇ᵀWQ̇`` under every limit of the run — the acceleration limit's box around the
previous step's velocity among them — and slows the joints as fast as that box allows (a
damper holds a drift below its safe value rather than pulling it back, which would never end).
Once ``Q̇ = 0`` is feasible it is the exact minimiser and is taken as it is (exactly 0, no
backend): the run's last step. The baseline, which holds no limit, stops in one step. The
stop's samples are reserved with the run's (:func:`room`), so recording it copies nothing.

**The bound.** With ``N = ‖Q̇‖_W`` (``W`` the step's metric, smallest weight ``w``) and the
slowest joint acceleration ``a`` (``qdd_max``), the previous velocity scaled by ``1 − s``,
``s = a dt / max |Q̇_i|``, is in the next step's box, so the QP's answer has ``N`` at least
``√w a dt`` smaller each step: braking takes at most ``N/(√w a)`` seconds while only the box and
the held tasks bind. A stop is given twice that and :data:`MARGIN` more (other limits, the
tasks' drift); a run still moving then ends with a failed step that names the fastest joint.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.robot import Robot
from dvqp.limits import AccelerationLimit, JointVelocityLimit
from dvqp.motion.jog import MAX_STEPS
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver, Step
from dvqp.step import Advance, Stepper, advance

MARGIN = 0.05
"""s: a stop's allowance beyond twice its bound (:func:`braking_steps`)."""

Array = NDArray[np.float64]


def braking_steps(qdot: Array, weights: Array, qdd_max: Array | None, dt: float) -> int:
    """Most steps of ``dt`` (s) a stop from the joint velocity ``qdot`` (rad/s, (n,)) may take:
    ``2 ‖Q̇‖_W / (√w_min q̈_min) + MARGIN`` seconds, at least one step (``weights`` the
    diagonal of ``W``; ``qdd_max`` rad/s², (n,); None: no acceleration limit, a stop within
    :data:`MARGIN`).

    Raises
    ------
    ParameterError
        The stop would take more than :data:`~dvqp.motion.jog.MAX_STEPS` steps (a ``qdd_max``
        so small that its record could not be held).
    """
    bound = 0.0
    if qdd_max is not None:
        norm = math.sqrt(float(np.sum(weights * qdot**2)))
        bound = 2.0 * norm / (math.sqrt(float(weights.min())) * float(qdd_max.min()))
    steps = (bound + MARGIN) / dt
    if not steps <= MAX_STEPS:  # a tiny qdd_max: a stop that no memory could record
        least = math.inf if qdd_max is None else float(qdd_max.min())
        raise ParameterError(
            "qdd_max",
            f"{least:.3g} rad/s^2: a stop would take about "
            f"{steps:.3g} steps of dt (at most {MAX_STEPS:.0e})",
        )
    return max(1, math.ceil(steps))


def _qdd_max(spec: StepSpec) -> Array | None:
    """The spec's joint acceleration limit, rad/s² (n,), or None."""
    accel = next((lim for lim in spec.limits if isinstance(lim, AccelerationLimit)), None)
    return None if accel is None else accel.qdd_max


def room(robot: Robot, resolver: Resolver, dt: float) -> int:
    """Steps to reserve for a stop: the bound from the velocity limits (a run that keeps them
    ends no faster) and the failed step; a stop that needs more grows the recorder then."""
    spec = resolver.spec
    limited = (
        resolver.holds_limits
        and np.all(np.isfinite(robot.qd_max))
        and any(isinstance(lim, JointVelocityLimit) for lim in spec.limits)
    )
    fastest = robot.qd_max if limited else np.zeros(robot.n)
    return braking_steps(fastest, spec.diagonal(robot.n), _qdd_max(spec), dt) + 1


def brake(
    stepper: Stepper,
    record: TrajectoryRecorder,
    first: int,
    dt: float,
    *,
    verify: bool,
    max_halvings: int,
) -> int:
    """Brake from the end of step ``first − 1`` until every joint has stopped; the number of
    braking steps recorded (0 if the run ended at rest).

    The stop may take the bound (:func:`braking_steps`) and one step more: a run still moving
    after the bound gets a failed last step (the arm held still, as every failed step) whose
    status says ``could not stop within qdd_max in T s`` and names the fastest joint.
    """
    last = record.arrays["qdot"][first - 1].copy() if first else np.zeros(stepper.robot.n)
    if not last.any():
        return 0
    spec = stepper.resolver.spec
    qdd_max = _qdd_max(spec)
    bound = braking_steps(last, spec.diagonal(stepper.robot.n), qdd_max, dt)
    if record.arrays["qdot"].shape[0] < first + bound + 1:  # beyond the room reserved
        record.extend(first + bound + 1 - record.arrays["qdot"].shape[0])
        stepper.record_into(record.arrays)
    still, started = np.zeros(4), time.perf_counter()
    stepper.stopping = True
    try:
        for k in range(first, first + bound):
            moved = advance(
                stepper, still, dt, verify=verify, max_halvings=max_halvings, record=k + 1
            )
            now = time.perf_counter()
            record.step(k, moved, now - started)
            started = now
            if moved.step.success and not moved.step.qdot.any():
                return k + 1 - first
            if moved.step.success:
                last = moved.step.qdot
    finally:
        stepper.stopping = False
    within = " within qdd_max" if qdd_max is not None else ""
    _not_stopped(stepper, record, first + bound, last, dt, f"{within} in {bound * dt:.3g} s")
    return bound + 1


def _not_stopped(
    stepper: Stepper, record: TrajectoryRecorder, k: int, qdot: Array, dt: float, within: str
) -> None:
    """Record step ``k`` as the failed end of a stop that took too long."""
    joint = int(np.argmax(np.abs(qdot)))
    status = (
        f"failed: could not stop{within}: joint{joint + 1} still at {abs(qdot[joint]):.3g} rad/s"
    )
    n = qdot.shape[0]
    stepper.observe(np.zeros(n), dt)
    stepper.record_at[0] = k + 1
    stepper.load(stepper.state.q.copy())  # the arm held still: the sample after the step
    stepper.record_at[0] = -1
    record.step(k, Advance(Step(np.zeros(n), False, status, math.inf, 0.0), 1), 0.0)
