"""What the resolvers' compiled solves share: their answer, the tasks' and limits' kernels.

The solves themselves: :class:`dvqp.compiled.qp.CompiledQP` (the QP on a fixed-structure
problem) and :class:`dvqp.compiled.pinv.CompiledPinv` (the paper's baseline).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled import ownership
from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.resolution.spec import StepSpec

Array = NDArray[np.float64]


@dataclass
class Answer:
    """What a compiled solve found: ``qdot`` (a view, valid until the next solve), rad/s,
    the hard tasks' error, the backend's iterations and time (s), and the status
    (``"optimal"``, ``"relaxed"``, ``"braking"``): the fields of
    :class:`~dvqp.resolution.step.Step` that a recorder reads. ``solve_time`` (s, the whole
    resolution) is set by the engine."""

    qdot: Array
    task_error: float
    iterations: int | None
    solver_time: float
    status: str = "optimal"
    solve_time: float = 0.0
    success = True


def task_kernels(spec: StepSpec, plan: StepPlan) -> list[Kernel] | None:
    """The hard tasks' kernels, or None if a task is soft or has no kernel of its own."""
    found = []
    for task in spec.tasks:
        ok, kernel = ownership.build(task, "kernel", plan)
        if not getattr(task, "hard", False) or not ok or kernel is None:
            return None
        found.append(kernel)
    return found


def limit_kernels(spec: StepSpec, plan: StepPlan) -> list[Kernel] | None:
    """The limits' row and bound kernels, or None if a limit has no kernel of its own (a
    limit whose kernel is None adds nothing)."""
    found = []
    for limit in spec.limits:
        ok, kernel = ownership.build(limit, "kernel", plan)
        if not ok:
            return None
        if kernel is not None:
            found.append(kernel)
    return found


def verifier_kernels(spec: StepSpec, plan: StepPlan) -> list[Kernel] | None:
    """The kernels of the exact quantities of every limit that verifies itself (has
    ``excess``), or None if one has no verifier of its own."""
    found = []
    for limit in spec.limits:
        if not hasattr(limit, "excess"):
            continue
        ok, kernel = ownership.build(limit, "verifier", plan)
        if not ok:
            return None
        if kernel is not None:
            found.append(kernel)
    return found


@njit(cache=True)
def scale(source: Array, factor: float, out: Array) -> None:
    """``out = factor · source`` (e.g. the QP's linear cost ``−λ ∂w/∂Q``)."""
    for i in range(source.shape[0]):
        out[i] = factor * source[i]


@njit(cache=True)
def open_box(lb: Array, ub: Array) -> None:
    """``lb = −inf``, ``ub = +inf``: the bounds kernels then intersect into them."""
    for i in range(lb.shape[0]):
        lb[i], ub[i] = -np.inf, np.inf


@njit(cache=True)
def finish(A: Array, b: Array, x: Array, q: Array, dt: float, out: Array) -> None:
    """``out = [‖A x − b‖∞, max |(q + dt·x) − q|]`` and ``q += dt·x`` (the step integrated in
    place)."""
    out[0] = task_error(A, b, x)
    largest = 0.0
    for i in range(q.shape[0]):
        moved = q[i] + dt * x[i]
        largest = max(largest, abs(moved - q[i]))  # as the reference measures the step
        q[i] = moved
    out[1] = largest


@njit(cache=True)
def task_error(A: Array, b: Array, x: Array) -> float:
    """``‖A x − b‖∞`` over the first ``A.shape[1]`` entries of x."""
    worst = 0.0
    for r in range(A.shape[0]):
        v = -b[r]
        for c in range(A.shape[1]):
            v += A[r, c] * x[c]
        worst = max(worst, abs(v))
    return worst
