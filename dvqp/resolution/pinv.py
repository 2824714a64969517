"""The paper's baseline (eq. 18): pseudoinverse plus null-space projection of ``∇w``, nested
over the levels of the tasks' priorities.

It uses the same tasks and objective as the QP and ignores the limits. Weighted least-norm form
with a positive diagonal ``W`` (``W = I`` gives eq. 18)::

    J̄_W⁺ = W⁻¹ J̄ᵀ (J̄ W⁻¹ J̄ᵀ + μ² I)⁻¹
    Q̇    = J̄_W⁺ ẋ + (I − J̄_W⁺ J̄) W⁻¹ g,        g = λ ∂w/∂Q

which is ``W⁻¹ g + J̄_W⁺ (ẋ − J̄ W⁻¹ g)``. With ``μ = 0`` this is exactly the minimiser of
``½ Q̇ᵀ W Q̇ − gᵀ Q̇`` subject to ``J̄ Q̇ = ẋ``: the QP without inequalities. With soft tasks
the metric becomes ``M = W + H`` (dense) and ``g`` takes their ``−c``; ``μ > 0`` (the damped,
singularity-robust inverse) is then refused.

Tasks at several priorities (levels ``A_k Q̇ = b_k``, 1 first) are nested: each level in the
null space of those above, ``∇w`` last in the null space of them all. With ``Q = M⁻¹`` (the
metric's inverse on what is still free) and ``Q̇ = 0`` at first, for each level::

    S_k = A_k Q A_kᵀ + μ² I
    Q̇  += Q A_kᵀ S_k⁻¹ (b_k − A_k Q̇)            level k's task in the null space above
    Q  −= Q A_kᵀ S_k⁻¹ A_k Q                     what level k leaves free

then ``Q̇ += Q g``. ``Q`` stays ``N M⁻¹`` with ``N`` the M-orthogonal projector on the levels'
common null space (``μ = 0``), so when no limit is active each level's answer is the QP's:
every level is met as well as the levels above let it (exactly where its ``A_k Q`` has full
row rank) and ``Q̇`` minimises the cost among those that do. With one level it is the formula above.

A level that cannot be met exactly, even with every limit inactive (a posture below other
tasks: more rows than the freedom the levels above leave; rows dependent there), is met in
least squares, as the lexicographic QP meets it (:mod:`dvqp.resolution.levels`): undamped,
``S_k⁻¹`` becomes ``D (D S_k D)⁺ D``, with ``D = diag(√w_i)`` the rows' weights within their
level (the relaxed QP's slack weights) and ``⁺`` the pseudoinverse whose rank drops the
eigenvalues of ``D S_k D`` at most :data:`RANK_TOLERANCE` of its largest (or, below the first
level, of the level's own size, which the levels above may have hidden). ``Q̇`` then moves
level k's residual ``‖D (A_k Q̇ − b_k)‖`` to its least value in what the levels above leave
free (the minimum-norm change in the metric), and ``Q`` keeps what it leaves free. A level of
full rank takes the Cholesky factor of ``S_k``; the eigenvalues (Jacobi's rotations,
:func:`symmetric_eigen`) are computed only where a pivot falls below that tolerance.
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

RANK_TOLERANCE = 1e-10
"""The rank of a level's Gram matrix ``S_k = A_k Q A_kᵀ`` (squared singular values): an
eigenvalue at most this fraction of its largest (below the first level: of the level's own
``max_r A_r M⁻¹ A_rᵀ``) counts as zero, so a level whose singular values fall below 1e-5 of
its size there is met in least squares. A Cholesky pivot that small sends the level there."""
SINGULAR_RCOND = RANK_TOLERANCE
"""The Cholesky pivots' ratio below which a level takes the pseudoinverse (the same value)."""

SINGULAR, NOT_DEFINITE = 1, 2
"""Statuses of :func:`pinv_step`: a level's Gram matrix not finite, or the metric not
positive definite."""
JACOBI_SWEEPS = 60
"""Most sweeps of Jacobi's rotations (:func:`symmetric_eigen`; some 6-10 reach double
precision on a level of 13 rows)."""


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

    def baseline_damping(self) -> float:
        """:attr:`damping`: the step is the baseline's."""
        return self.damping


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


@njit
def _solve(factor: Array, x: Array) -> None:
    """``x = (L Lᵀ)⁻¹ x`` in place, ``factor`` from :func:`_cholesky`. Called, not inlined:
    inlined in its four places it cost :func:`pinv_step` about 0.8 s more to compile, for
    the same step time."""
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


@njit
def symmetric_eigen(a: Array, vectors: Array) -> bool:
    """Eigenvalues of the symmetric ``a`` (m, m) onto its diagonal, in place, and its
    eigenvectors into the columns of ``vectors`` (m, m): ``a₀ = V diag(a) Vᵀ`` (cyclic Jacobi
    rotations until the off-diagonal part is 1e-30 of the whole, squared). False if ``a`` is
    not finite."""
    m = a.shape[0]
    total = 0.0
    for i in range(m):
        for j in range(m):
            vectors[i, j] = 1.0 if i == j else 0.0
            total += a[i, j] * a[i, j]
    if not math.isfinite(total):
        return False
    for _ in range(JACOBI_SWEEPS):
        off = 0.0
        for p in range(m):
            for q in range(p + 1, m):
                off += a[p, q] * a[p, q]
        if off <= 1e-30 * total:
            break
        for p in range(m):
            for q in range(p + 1, m):
                apq = a[p, q]
                if apq == 0.0:
                    continue
                theta = (a[q, q] - a[p, p]) / (2.0 * apq)
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                for k in range(m):  # a J: columns p and q
                    akp, akq = a[k, p], a[k, q]
                    a[k, p], a[k, q] = c * akp - s * akq, s * akp + c * akq
                for k in range(m):  # Jᵀ (a J): rows p and q
                    apk, aqk = a[p, k], a[q, k]
                    a[p, k], a[q, k] = c * apk - s * aqk, s * apk + c * aqk
                for k in range(m):
                    vkp, vkq = vectors[k, p], vectors[k, q]
                    vectors[k, p], vectors[k, q] = c * vkp - s * vkq, s * vkp + c * vkq
    return True


@njit
def _pseudo_inverse(gram: Array, weights: Array, first: int, floor: float) -> bool:
    """``gram`` (m, m; ``S_k``, not factored) replaced by ``D (D S_k D)⁺ D`` (``D =
    diag(√weights[first : first + m])``), eigenvalues of ``D S_k D`` at most :data:`RANK_TOLERANCE`
    of the larger of its largest and ``floor`` (a lower level's own size) dropped. False if
    ``S_k`` is not finite."""
    m = gram.shape[0]
    root = np.empty(m)
    for r in range(m):
        root[r] = math.sqrt(weights[first + r])
    for r in range(m):
        for t in range(m):
            gram[r, t] *= root[r] * root[t]
    vectors = np.empty((m, m))
    if not symmetric_eigen(gram, vectors):
        return False
    top = 0.0
    for r in range(m):
        top = max(top, floor * weights[first + r])
    for k in range(m):
        top = max(top, gram[k, k])
    inverse = np.zeros(m)
    for k in range(m):
        if gram[k, k] > RANK_TOLERANCE * top:
            inverse[k] = 1.0 / gram[k, k]
    for r in range(m):
        for t in range(m):
            v = 0.0
            for k in range(m):
                v += vectors[r, k] * inverse[k] * vectors[t, k]
            gram[r, t] = root[r] * v * root[t]
    return True


@njit(inline="always")
def _apply(gram: Array, pseudo: bool, x: Array, scratch: Array) -> None:
    """``x = S⁻¹ x`` in place: through the Cholesky factor ``gram`` (:func:`_solve`), or, if
    ``pseudo``, by the matrix ``gram`` holds (:func:`_pseudo_inverse`)."""
    if not pseudo:
        _solve(gram, x)
        return
    m = gram.shape[0]
    for r in range(m):
        v = 0.0
        for t in range(m):
            v += gram[r, t] * x[t]
        scratch[r] = v
    for r in range(m):
        x[r] = scratch[r]


@njit(inline="always")
def _inverse(P: Array, dense: bool, weights: Array, info: Array, Q: Array) -> bool:
    """``Q = M⁻¹``: ``diag(1/weights)``, or the dense ``P``'s inverse column by column (False
    if ``P`` is not positive definite)."""
    n = Q.shape[0]
    if not dense:
        for c in range(n):
            Q[c, c] = 1.0 / weights[c]
        return True
    factor = P.copy()
    if not _cholesky(factor, info):
        return False
    column = np.empty(n)
    for c in range(n):
        for r in range(n):
            column[r] = 1.0 if r == c else 0.0
        _solve(factor, column)
        for r in range(n):
            Q[r, c] = column[r]
    return True


@njit(inline="always")
def _project(Q, qa, gram, pseudo, cost, x, column, scratch, out):  # type: ignore[no-untyped-def]
    """``out = x − (Q − Q Aᵀ S⁻¹ (Q Aᵀ)ᵀ) cost`` without forming the projected ``Q``
    (``qa = Q Aᵀ`` (n, m), ``gram`` the factor of ``S`` or its pseudoinverse (``pseudo``,
    :func:`_apply`), ``column``, ``scratch`` (m,)): ``x − Q cost + qa S⁻¹ (qaᵀ cost)``."""
    n, m = qa.shape
    for r in range(m):
        v = 0.0
        for c in range(n):
            v += qa[c, r] * cost[c]
        column[r] = v
    _apply(gram, pseudo, column, scratch)
    for c in range(n):
        v = x[c]
        for j in range(n):
            v -= Q[c, j] * cost[j]
        for r in range(m):
            v += qa[c, r] * column[r]
        out[c] = v


@njit(inline="always")
def _level(
    A, b, rows, first, m, Q, inverse, x, damping, info, lower, diagonal, last, cost, out
) -> bool:  # type: ignore[no-untyped-def]
    """Level ``A[first : first + m]``: ``x += Q Aᵀ S⁻¹ (b − A x)`` and ``Q −= Q Aᵀ S⁻¹ A Q``,
    ``S⁻¹`` the weighted pseudoinverse where ``S`` is not safely positive definite (undamped:
    a Cholesky pivot at most :data:`RANK_TOLERANCE` of the largest or, ``lower`` (below the
    first level), of the level's own size through ``inverse`` = M⁻¹; ``rows`` the rows'
    weights, :func:`_pseudo_inverse`); False if ``S`` is not finite (``diagonal``: ``Q`` is
    the first level's ``M⁻¹`` of a diagonal metric). The ``last`` level writes the step
    instead, ``out = x − Q cost`` with the ``Q`` it would leave (:func:`_project`), and
    leaves ``Q`` as it was."""
    n = A.shape[1]
    qa, gram, rhs = np.empty((n, m)), np.empty((m, m)), np.empty(m)  # Q A_kᵀ, S_k
    column, scratch = np.empty(m), np.empty(m)
    for c in range(n):
        for r in range(m):
            if diagonal:  # the sum below of a diagonal Q, bit for bit (its zeros add +0)
                qa[c, r] = 0.0 + Q[c, c] * A[first + r, c]
                continue
            acc = 0.0
            for j in range(n):
                acc += Q[c, j] * A[first + r, j]
            qa[c, r] = acc
    scale = 0.0  # a lower level's own size, before its projection: a row Q hides
    for r in range(m):
        v = b[first + r]
        for c in range(n):
            v -= A[first + r, c] * x[c]
        rhs[r] = v
        for t in range(m):
            acc = 0.0
            for c in range(n):
                acc += A[first + r, c] * qa[c, t]
            gram[r, t] = acc
        gram[r, r] += damping * damping
        own = 0.0
        for c in range(n if lower else 0):
            for j in range(n):
                own += A[first + r, c] * inverse[c, j] * A[first + r, j]
        scale = max(scale, own)
    raw = gram.copy()
    pseudo = not _cholesky(gram, info) or (
        damping == 0.0 and info[0] <= SINGULAR_RCOND * max(info[1], scale)
    )
    if pseudo:
        gram = raw
        if not _pseudo_inverse(gram, rows, first, scale):
            return False
    _apply(gram, pseudo, rhs, scratch)
    for c in range(n):
        v = 0.0
        for r in range(m):
            v += qa[c, r] * rhs[r]
        x[c] += v
    if last:  # the last level: Q is read once more, as out = x − Q_new c
        _project(Q, qa, gram, pseudo, cost, x, column, scratch, out)
        return True
    for c in range(n):  # Q −= Q A_kᵀ S_k⁻¹ (Q A_kᵀ)ᵀ, column by column
        for r in range(m):
            column[r] = qa[c, r]
        _apply(gram, pseudo, column, scratch)
        for i in range(n):
            v = 0.0
            for r in range(m):
                v += qa[i, r] * column[r]
            Q[i, c] -= v
    return True


@njit(separate=True)
def pinv_step(A, b, levels, rows, cost, weights, P, dense, damping, info, out) -> int:  # type: ignore[no-untyped-def]
    """``out``: the nested step of the module docstring over the levels ``A[levels[k] :
    levels[k+1]]`` (``levels`` (L + 1,); ``rows`` (m,) the rows' weights within their level),
    with ``g = −cost`` and ``M = diag(weights)``, or the dense ``P`` if ``dense``. A level
    that cannot be met exactly is met in least squares (the module docstring). Returns −1,
    :data:`SINGULAR` (a level's Gram matrix not finite; ``info[2]`` the level k) or
    :data:`NOT_DEFINITE` (the metric); ``info[:2]`` the last Cholesky's pivots' extreme
    squares."""
    n = A.shape[1]
    Q = np.zeros((n, n))  # M⁻¹, then what the levels leave free
    if not _inverse(P, dense, weights, info, Q):
        return NOT_DEFINITE
    inverse = Q.copy() if levels.shape[0] > 2 else Q  # M⁻¹, kept for the lower levels' scale
    x = np.zeros(n)
    last = -1  # the last level with rows: it writes the step
    for level in range(levels.shape[0] - 1):
        if levels[level + 1] > levels[level]:
            last = level
    for level in range(levels.shape[0] - 1):
        first, m = levels[level], levels[level + 1] - levels[level]
        diagonal = not dense and level == 0
        if m > 0 and not _level(
            A,
            b,
            rows,
            first,
            m,
            Q,
            inverse,
            x,
            damping,
            info,
            level > 0,
            diagonal,
            level == last,
            cost,
            out,
        ):
            info[2] = level
            return SINGULAR
    if last == -1:  # no task row: the objective's step alone
        for c in range(n):
            v = x[c]
            for j in range(n):
                v -= Q[c, j] * cost[j]
            out[c] = v
    return -1
