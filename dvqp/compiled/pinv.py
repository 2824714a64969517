"""The paper's baseline (eq. 18) compiled: pseudoinverse plus null-space projection of ``∇w``."""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.compiled.solve import Answer, scale
from dvqp.resolution.pinv import SINGULAR_RCOND
from dvqp.resolution.spec import StepSpec

Array = NDArray[np.float64]


@njit(cache=True)
def pinv_step(A: Array, b: Array, g: Array, inv_w: Array, damping: float, out: Array) -> int:
    """``out = W⁻¹g + J̄_W⁺ (ẋ − J̄ W⁻¹ g)`` (see :func:`~dvqp.resolution.pinv.weighted_pinv_step`)
    by a Cholesky factor of ``J̄ W⁻¹ J̄ᵀ + μ² I``; returns −1, or 1 if that is not (safely)
    positive definite (the caller then lets the reference path raise its error)."""
    m, n = A.shape
    gram, rhs = np.empty((m, m)), np.empty(m)
    for r in range(m):
        v = b[r]
        for c in range(n):
            v -= A[r, c] * inv_w[c] * g[c]
        rhs[r] = v
        for s in range(r + 1):
            acc = 0.0
            for c in range(n):
                acc += A[r, c] * inv_w[c] * A[s, c]
            gram[r, s] = acc
        gram[r, r] += damping * damping
    lo, hi = math.inf, 0.0
    for j in range(m):  # Cholesky, lower, in place
        d = gram[j, j]
        for p in range(j):
            d -= gram[j, p] * gram[j, p]
        if not d > 0.0:
            return 1
        piv = math.sqrt(d)
        gram[j, j] = piv
        lo, hi = min(lo, d), max(hi, d)
        for r in range(j + 1, m):
            v = gram[r, j]
            for p in range(j):
                v -= gram[r, p] * gram[j, p]
            gram[r, j] = v / piv
    if damping == 0.0 and lo <= SINGULAR_RCOND * hi:
        return 1
    for r in range(m):  # forward then back substitution
        v = rhs[r]
        for p in range(r):
            v -= gram[r, p] * rhs[p]
        rhs[r] = v / gram[r, r]
    for r in range(m - 1, -1, -1):
        v = rhs[r]
        for p in range(r + 1, m):
            v -= gram[p, r] * rhs[p]
        rhs[r] = v / gram[r, r]
    for c in range(n):
        v = g[c]
        for r in range(m):
            v += A[r, c] * rhs[r]
        out[c] = inv_w[c] * v
    return -1


class CompiledPinv:
    """The baseline's step (diagonal ``W``, no soft tasks) in one kernel.

    Parameters
    ----------
    spec, plan
        The run's spec and plan (finalised).
    damping
        ``μ``.
    gain
        ``λ``.
    """

    solves_in_prepare = True
    """The step is computed by :attr:`kernels` (fused into the engine's prepare call)."""

    def __init__(self, spec: StepSpec, plan: StepPlan, damping: float, gain: float) -> None:
        self.plan = plan
        st = plan.stacked
        g, self.x = np.zeros(plan.n), np.zeros(plan.n)
        inv_w = 1.0 / spec.diagonal(plan.n)
        self.kernels = [
            Kernel(scale, (plan.objective_gradient, gain, g)),
            Kernel(pinv_step, (st["A"], st["b"], g, inv_w, float(damping), self.x), True),
        ]
        """What computes the step once the tasks' rows are written."""

    def solve(self, status: int) -> Answer | None:
        """The step computed by :attr:`kernels` (``status`` −1), or None if the Gram matrix
        was (nearly) singular."""
        if status != -1:
            return None
        return Answer(self.x, 0.0, None, 0.0)

    def reset(self) -> None:
        """Nothing to forget."""
