"""The compiled KKT kernel behind :mod:`solvers.kkt` (see there for what it computes).

:func:`kernel` and :func:`stacked` compile (or load numba's cache) at their first call, for
their one declared signature (:func:`solvers.jit.compiled_on_first_call`); both call one
separately compiled body, :func:`_residuals`, on read-only arrays: it compiles once, for
whichever of them runs first.
"""

from __future__ import annotations

import math

import numpy as np
from numba import types
from numba.core.extending import intrinsic
from numba.core.imputils import impl_ret_borrowed

from .jit import compiled_on_first_call, njit

_VEC = types.Array(types.float64, 1, "C", readonly=True)
_MAT = types.Array(types.float64, 2, "C", readonly=True)
_SIGNATURE = types.UniTuple(types.float64, 8)(
    _MAT, _VEC, _MAT, _VEC, _MAT, _VEC, _VEC, _VEC, _VEC, _VEC, _VEC, _VEC, types.int64
)

#: ``flags`` bits of :func:`kernel`: which of ``lb``, ``ub``, ``y``, ``z``, ``z_box`` are given.
HAS_LB, HAS_UB, HAS_Y, HAS_Z, HAS_BOX = 1, 2, 4, 8, 16
#: Bits of the kernel's ``code`` (its first value): ``x`` is finite, every multiplier the
#: problem needs is given; ``MISFIT`` (-1) when an array's size does not fit the others.
FINITE, DUALS, MISFIT = 1, 2, -1
#: The kernels' values on a misfit.
MISFITTING = (float(MISFIT),) + (math.nan,) * 7
#: Reassociation only, so that the dot products vectorise (~0.15 µs a call); no finite-math
#: assumption: NaN and inf keep their meaning. Both kernels call the same compiled body, so
#: they give bitwise the same values on the same data (tests/solvers/test_daqp_fast.py holds
#: them to it).
_FASTMATH = {"reassoc"}


@njit(fastmath=_FASTMATH)
def _max(a: float, b: float) -> float:
    """``max(a, b)`` that propagates NaN from either side."""
    return a if (a >= b or a != a) else b


@njit(fastmath=_FASTMATH)
def _weight(slack: float) -> float:
    """``|slack|``, or 1 for an infinite slack (complementarity of an inactive row)."""
    return abs(slack) if math.isfinite(slack) else 1.0


@njit(fastmath=_FASTMATH)
def _fit(P, q, A, b, G, h, lb, ub, x, y, z, z_box, flags):  # type: ignore[no-untyped-def]
    """:data:`MISFIT` if a size does not fit ``x``'s, else :data:`DUALS` or 0."""
    n, m, p = x.shape[0], A.shape[0], G.shape[0]
    if P.shape[0] != n or P.shape[1] != n or q.shape[0] != n or b.shape[0] != m:
        return MISFIT
    if h.shape[0] != p or (m > 0 and A.shape[1] != n) or (p > 0 and G.shape[1] != n):
        return MISFIT
    if (flags & HAS_LB and lb.shape[0] != n) or (flags & HAS_UB and ub.shape[0] != n):
        return MISFIT
    box = flags & (HAS_LB | HAS_UB)
    if (m > 0 and flags & HAS_Y and y.shape[0] != m) or (
        p > 0 and flags & HAS_Z and z.shape[0] != p
    ):
        return MISFIT
    if box and flags & HAS_BOX and z_box.shape[0] != n:
        return MISFIT
    if (m > 0 and not flags & HAS_Y) or (p > 0 and not flags & HAS_Z):
        return 0
    return 0 if box and not flags & HAS_BOX else DUALS


@njit(fastmath=_FASTMATH)
def _bounds(lb, ub, x, z_box, flags, duals, grad):  # type: ignore[no-untyped-def]
    """``(bounds, complementarity of the bounds, lbᵀz_box⁻ + ubᵀz_box⁺ over finite bounds)``,
    adding ``z_box`` to ``grad``."""
    bounds = complementarity = gap = 0.0
    for j in range(x.shape[0]):
        if flags & HAS_UB:
            bounds = _max(bounds, -(ub[j] - x[j]))
        if flags & HAS_LB:
            bounds = _max(bounds, -(x[j] - lb[j]))
        if not duals or not flags & (HAS_LB | HAS_UB):
            continue
        zj = z_box[j]
        grad[j] += zj
        if flags & HAS_UB and zj > 0.0 and math.isfinite(ub[j]):
            gap += ub[j] * zj
        if flags & HAS_LB and zj < 0.0 and math.isfinite(lb[j]):
            gap += lb[j] * zj
        if flags & HAS_UB:  # z_box > 0 pairs with the upper slack
            complementarity = _max(complementarity, max(zj, 0.0) * _weight(ub[j] - x[j]))
        else:  # a multiplier on a missing bound is all error
            complementarity = _max(complementarity, zj)
        if flags & HAS_LB:  # z_box < 0 pairs with the lower slack
            complementarity = _max(complementarity, max(-zj, 0.0) * _weight(x[j] - lb[j]))
        else:
            complementarity = _max(complementarity, -zj)
    return bounds, complementarity, gap


@intrinsic
def _readonly(typingctx, array):  # type: ignore[no-untyped-def]
    """``array`` typed as read-only (the same array): :func:`stacked`'s views of its buffer
    then have :func:`kernel`'s types, and :func:`_residuals` one specialisation."""
    if not isinstance(array, types.Array):
        return None

    def codegen(context, builder, signature, args):  # type: ignore[no-untyped-def]
        return impl_ret_borrowed(context, builder, signature.return_type, args[0])

    return array.copy(readonly=True)(array), codegen


@njit(separate=True, fastmath=_FASTMATH)
def _residuals(P, q, A, b, G, h, lb, ub, x, y, z, z_box, flags):  # type: ignore[no-untyped-def]
    """The body of :func:`kernel` and :func:`stacked` (compiled once, on read-only arrays)."""
    code = _fit(P, q, A, b, G, h, lb, ub, x, y, z, z_box, flags)
    if code == MISFIT:
        return MISFITTING
    duals = code == DUALS
    n = x.shape[0]
    code |= FINITE
    grad = np.empty(n)
    scale = gap = 0.0  # gap: xᵀPx + qᵀx + bᵀy + hᵀz (+ the bounds' terms), finite rows only
    for j in range(n):
        if not math.isfinite(x[j]):
            code &= ~FINITE
        s = 0.0
        for k in range(n):
            s += P[j, k] * x[k]
        scale = _max(_max(scale, abs(s)), abs(q[j]))
        grad[j] = s + q[j]
        gap += (s + q[j]) * x[j]
    equality = inequality = complementarity = 0.0
    for i in range(A.shape[0]):
        r = -b[i]
        for j in range(n):
            r += A[i, j] * x[j]
            if duals:
                grad[j] += y[i] * A[i, j]
        equality = _max(equality, abs(r))
        if duals:
            gap += b[i] * y[i]
    for i in range(G.shape[0]):
        s = 0.0
        for j in range(n):
            s += G[i, j] * x[j]
            if duals:
                grad[j] += z[i] * G[i, j]
        inequality = _max(inequality, -(h[i] - s))  # slack h - G x
        if duals:
            complementarity = _max(complementarity, -z[i])
            complementarity = _max(complementarity, max(z[i], 0.0) * _weight(h[i] - s))
            if math.isfinite(h[i]):
                gap += h[i] * z[i]
    bounds, box, box_gap = _bounds(lb, ub, x, z_box, flags, duals, grad)
    if not duals:
        return float(code), equality, inequality, bounds, math.nan, math.nan, scale, math.nan
    stationarity = 0.0
    for j in range(n):
        stationarity = _max(stationarity, abs(grad[j]))
    complementarity = _max(complementarity, box)
    gap = abs(gap + box_gap)
    return float(code), equality, inequality, bounds, stationarity, complementarity, scale, gap


@compiled_on_first_call(_SIGNATURE, fastmath=_FASTMATH)
def kernel(
    P: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    z_box: np.ndarray,
    flags: int,
) -> tuple[float, float, float, float, float, float, float, float]:
    """``(code, equality, inequality, bounds, stationarity, complementarity, scale, gap)``.

    ``code`` is :data:`MISFIT` (the rest NaN), or the bits :data:`FINITE` and
    :data:`DUALS`; stationarity, complementarity and the duality gap are NaN placeholders
    without :data:`DUALS`.
    """
    return _residuals(P, q, A, b, G, h, lb, ub, x, y, z, z_box, flags)


@njit(fastmath=_FASTMATH)
def stacked_values(
    data: np.ndarray, x: np.ndarray, lam: np.ndarray, n: int, p: int, m: int, ms: int, flags: int
) -> tuple[float, float, float, float, float, float, float, float]:
    """:func:`kernel` on DAQP's stacked copy of a problem, with DAQP's multipliers.

    ``data`` is laid out as :func:`solvers._fast.stack` writes it (``P`` as ``H``, ``q`` as
    ``f``, ``[G; A]``, ``[ub, h, b]``, ``[lb, -inf, b]``), ``lam`` is ``[z_box, z, y]``
    (``ms`` entries of ``z_box``, ``ms`` being 0 or ``n``) and ``flags`` holds
    :data:`HAS_LB` / :data:`HAS_UB` as the problem has them. The same code on a bitwise copy
    of the data: the very values :func:`kernel` gives on the problem's own arrays. Three
    arrays to pass instead of twelve: the dispatch is ~0.5 µs cheaper.
    """
    rows = ms + p + m
    size = n * (n + 1 + p + m) + 2 * rows
    if data.shape[0] != size or x.shape[0] != n or lam.shape[0] != rows or ms not in (0, n):
        return MISFITTING
    data, x, lam = _readonly(data), _readonly(x), _readonly(lam)
    f, M = n * n, n * n + n  # offsets of f, M, upper, lower in data
    upper = M + (p + m) * n
    lower = upper + rows
    G = data[M : M + p * n].reshape((p, n))
    A = data[M + p * n : upper].reshape((m, n))
    box = flags & (HAS_LB | HAS_UB) and ms
    return _residuals(
        data[:f].reshape((n, n)),
        data[f:M],
        A,
        data[upper + ms + p : lower],
        G,
        data[upper + ms : upper + ms + p],
        data[lower : lower + ms] if flags & HAS_LB else data[:0],
        data[upper : upper + ms] if flags & HAS_UB else data[:0],
        x,
        lam[ms + p :],
        lam[ms : ms + p],
        lam[:ms],
        flags | HAS_Y | HAS_Z | (HAS_BOX if box else 0),
    )


@compiled_on_first_call(
    # Writable arrays (DAQP's buffer and answers): an exact match, the quickest dispatch.
    types.UniTuple(types.float64, 8)(*(types.float64[::1],) * 3, *(types.int64,) * 5),
    fastmath=_FASTMATH,
)
def stacked(
    data: np.ndarray, x: np.ndarray, lam: np.ndarray, n: int, p: int, m: int, ms: int, flags: int
) -> tuple[float, float, float, float, float, float, float, float]:
    """:func:`stacked_values`, compiled for its one signature, called from Python."""
    return stacked_values(data, x, lam, n, p, m, ms, flags)
