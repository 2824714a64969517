r"""A refusal proved from the problem data: multipliers that no acceptable answer can meet.

The residual check (:func:`solvers.residuals.accepts`) accepts an ``x`` only if
``|A x − b| ≤ τ``, ``G x − h ≤ τ`` and ``lb − τ ≤ x ≤ ub + τ`` hold row by row (``τ`` its
absolute tolerance). Multipliers ``y`` (any sign) and ``z ≥ 0`` bound ``vᵀx`` for every such
``x``, with ``v = Aᵀy + Gᵀz``, from above:

.. math::

    v^T x = y^T A x + z^T G x \le y^T b + z^T h + τ (\|y\|_1 + \|z\|_1) = U,

and the box bounds it from below: ``vᵀx ≥ L = Σ_j min(v_j (lb_j − τ), v_j (ub_j + τ))``. If
``L > U`` no ``x`` passes the check: the problem is refused whatever a solver would answer
(Farkas' lemma: such multipliers exist whenever the constraints are infeasible by more than
the tolerance). :func:`refuted` makes that test on the data a solve would be given, in
floating point with a margin of ``1e-12`` of the terms' magnitude (rounding errors are far
smaller); a row with an infinite bound, or a one-sided row's multiplier of the wrong sign,
takes no part (its multiplier counts as 0, which keeps the test sound); a product that
underflows (below the least normal float) proves nothing.

Where a sequence of problems stays infeasible (the strict task of a streak of steps that
cannot meet it), multipliers that proved one problem infeasible, or the answer's multipliers
of the same constraints with the task relaxed, often prove the next: that refusal then needs
no solve (:attr:`solvers.daqp_.DaqpBackend.refutes`).
"""

from __future__ import annotations

import math

import numpy as np

from .jit import njit

MARGIN = 1e-12
"""How far (relative to the magnitude of its terms) ``L`` must exceed ``U``."""
NORMAL = 2.2250738585072014e-308
"""The least normal float64: a product of nonzero factors below it lost its relative
precision (underflow), and the test no longer bounds its error: nothing is proved then."""


@njit
def refuted(
    data: np.ndarray,
    lam: np.ndarray,
    n: int,
    p: int,
    m: int,
    ms: int,
    has_lb: bool,
    has_ub: bool,
    tolerance: float,
) -> bool:
    """Whether the multipliers ``lam`` prove that no ``x`` passes the residual check at
    ``tolerance`` on the problem in ``data`` (see the module docstring).

    Parameters
    ----------
    data
        The problem as :func:`solvers._fast.stack_into` lays it out: ``H`` (n, n), ``f`` (n),
        ``[G; A]`` ((p + m), n), ``upper = [ub, h, b]`` and ``lower = [lb, ·, b]`` (ms + p + m
        each; ``ms`` is 0 or ``n``).
    lam
        (ms + p + m,) ``[z_box, z, y]`` (``z_box`` takes no part: the box enters through
        ``lb``, ``ub``).
    has_lb, has_ub
        Whether the box's lower and upper bounds are given (else they are infinite).
    tolerance
        The check's absolute tolerance ``τ`` (≥ 0).
    """
    rows = ms + p + m
    M = n * n + n
    upper = M + (p + m) * n
    lower = upper + rows
    sums = np.zeros(2 * n)  # v, then Σ |λ_i M_ij|: the magnitude of v's terms
    v, size = sums[:n], sums[n:]
    top, scale = 0.0, 0.0
    for i in range(p + m):
        weight, bound = lam[ms + i], data[upper + ms + i]
        if i < p and not weight > 0.0:
            continue  # a one-sided row: only z ≥ 0 bounds G x from above
        if weight == 0.0 or not math.isfinite(bound) or not math.isfinite(weight):
            continue
        if _underflows(weight, bound) or _underflows(weight, tolerance):
            return False
        top += weight * bound + tolerance * abs(weight)
        scale += abs(weight * bound) + tolerance * abs(weight)
        row = M + i * n
        for j in range(n):  # weight is finite and nonzero: _underflows(weight, entry) is
            entry = data[row + j]  # a nonzero entry whose term is below NORMAL
            term = weight * entry
            magnitude = abs(term)
            if magnitude < NORMAL and entry != 0.0:
                return False
            v[j] += term
            size[j] += magnitude
    least = 0.0
    for j in range(n):
        if size[j] == 0.0:
            continue  # every row's entry is 0 (no product underflowed): v_j = 0 exactly
        lo = data[lower + j] - tolerance if has_lb and ms > 0 else -math.inf
        hi = data[upper + j] + tolerance if has_ub and ms > 0 else math.inf
        side = lo if v[j] > 0.0 else hi
        if v[j] != 0.0 and _underflows(v[j], side):
            return False
        least += v[j] * side if v[j] != 0.0 else 0.0
        scale += size[j] * max(abs(lo), abs(hi))
    return least - top > MARGIN * scale  # False on NaN or an infinite side


@njit(inline="always")
def _underflows(a: float, b: float) -> bool:
    """Whether ``a · b`` of nonzero finite factors lost its relative precision (below
    :data:`NORMAL`)."""
    product = a * b
    return a != 0.0 and b != 0.0 and abs(product) < NORMAL and math.isfinite(b)
