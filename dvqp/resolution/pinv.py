"""The paper's baseline (eq. 18): pseudoinverse plus null-space projection of ``∇w``.

It uses the same tasks and objective as the QP and ignores the limits. Weighted least-norm form
with a positive diagonal ``W`` (``W = I`` gives eq. 18)::

    J̄_W⁺ = W⁻¹ J̄ᵀ (J̄ W⁻¹ J̄ᵀ + μ² I)⁻¹
    Q̇    = J̄_W⁺ ẋ + (I − J̄_W⁺ J̄) W⁻¹ g,        g = λ ∂w/∂Q

which is ``W⁻¹ g + J̄_W⁺ (ẋ − J̄ W⁻¹ g)``. With ``μ = 0`` this is exactly the minimiser of
``½ Q̇ᵀ W Q̇ − gᵀ Q̇`` subject to ``J̄ Q̇ = ẋ``: the QP without inequalities. With soft tasks
the metric becomes ``M = W + H`` (dense) and ``g`` takes their ``−c``; ``μ > 0`` (the damped,
singularity-robust inverse) is then refused.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver
from solvers.jit import njit

Array = NDArray[np.float64]

SINGULAR_RCOND = 1e-10
"""Smallest ratio of Cholesky pivots of ``J̄ M⁻¹ J̄ᵀ`` (about its reciprocal condition number)
below which the undamped inverse is refused."""

SINGULAR, NOT_DEFINITE = 1, 2
"""Statuses of :func:`pinv_step`: the task's Gram matrix, or the metric, is not positive
definite (enough)."""


class PseudoinverseResolver(Resolver):
    """The paper's baseline resolver (name ``"pinv"``) on the tasks and objective of a spec.

    Parameters
    ----------
    spec
        Tasks, objective and weights (its limits are not used: the baseline holds none).
    damping
        ``μ >= 0`` of the damped inverse; 0 reproduces eq. 18 and fails at singularities.
    """

    name = "pinv"
    holds_limits = False

    def __init__(self, spec: StepSpec, damping: float = 0.0) -> None:
        super().__init__(spec)
        self.damping = _validate.positive("damping", damping, strict=False)


@njit
def _cholesky(a: Array, info: Array) -> bool:
    """``a = L Lᵀ`` in place (lower), pivots' smallest and largest squares into ``info``;
    False if ``a`` is not positive definite."""
    lo, hi = math.inf, 0.0
    for j in range(a.shape[0]):
        d = a[j, j]
        for p in range(j):
            d -= a[j, p] * a[j, p]
        if not d > 0.0:
            info[0], info[1] = d, max(hi, d)
            return False
        piv = math.sqrt(d)
        a[j, j] = piv
        lo, hi = min(lo, d), max(hi, d)
        for r in range(j + 1, a.shape[0]):
            v = a[r, j]
            for p in range(j):
                v -= a[r, p] * a[j, p]
            a[r, j] = v / piv
    info[0], info[1] = lo, hi
    return True


@njit(inline="always")
def _solve(factor: Array, x: Array) -> None:
    """``x = (L Lᵀ)⁻¹ x`` in place, ``factor`` from :func:`_cholesky`."""
    m = factor.shape[0]
    for r in range(m):
        v = x[r]
        for p in range(r):
            v -= factor[r, p] * x[p]
        x[r] = v / factor[r, r]
    for r in range(m - 1, -1, -1):
        v = x[r]
        for p in range(r + 1, m):
            v -= factor[p, r] * x[p]
        x[r] = v / factor[r, r]


@njit(separate=True)
def pinv_step(A, b, cost, weights, P, dense, damping, info, out) -> int:  # type: ignore[no-untyped-def]
    """``out = M⁻¹g + M⁻¹Aᵀ (A M⁻¹ Aᵀ + μ² I)⁻¹ (b − A M⁻¹ g)`` with ``g = −cost`` and
    ``M = diag(weights)``, or the dense ``P`` if ``dense``. Returns −1, :data:`SINGULAR` (the
    Gram matrix not safely positive definite; ``info`` its pivots' extreme squares) or
    :data:`NOT_DEFINITE` (the metric)."""
    m, n = A.shape
    mj, mg = np.empty((n, m)), np.empty(n)  # M⁻¹ Aᵀ, M⁻¹ g
    for c in range(n):
        mg[c] = -cost[c]
        for r in range(m):
            mj[c, r] = A[r, c]
    if dense:
        factor = P.copy()
        if not _cholesky(factor, info):
            return NOT_DEFINITE
        _solve(factor, mg)
        column = np.empty(n)
        for r in range(m):
            for c in range(n):
                column[c] = mj[c, r]
            _solve(factor, column)
            for c in range(n):
                mj[c, r] = column[c]
    else:
        for c in range(n):
            mg[c] /= weights[c]
            for r in range(m):
                mj[c, r] /= weights[c]
    gram, rhs = np.empty((m, m)), np.empty(m)
    for r in range(m):
        v = b[r]
        for c in range(n):
            v -= A[r, c] * mg[c]
        rhs[r] = v
        for s in range(m):
            acc = 0.0
            for c in range(n):
                acc += A[r, c] * mj[c, s]
            gram[r, s] = acc
        gram[r, r] += damping * damping
    if not _cholesky(gram, info) or (damping == 0.0 and info[0] <= SINGULAR_RCOND * info[1]):
        return SINGULAR
    _solve(gram, rhs)
    for c in range(n):
        v = mg[c]
        for r in range(m):
            v += mj[c, r] * rhs[r]
        out[c] = v
    return -1
