r"""Compiled KKT residuals: :func:`solvers.residuals.kkt_residuals` in one numba kernel.

Same formulas and scale as the NumPy reference in :mod:`solvers.residuals` (the tests hold
them to 1e-12 relative), including ``+inf`` in ``h``/``lb``/``ub`` (an infinite slack
counts as 1 in complementarity), missing blocks and missing multipliers. One difference,
on data the regular :class:`~solvers.Problem` rejects: a NaN anywhere (e.g. in a trusted
problem's ``h``) makes the affected residual NaN, hence a failed check, where the
reference's ``max(0.0, nan)`` can yield 0.

The kernel has a single eager signature (read-only float64 C-contiguous arrays, which
writable arrays also match), compiled once and cached on disk (``cache=True``); missing
blocks are passed as empty arrays, so one call costs about 1-2 µs on a dvqp-sized QP.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, types

from .exceptions import ProblemShapeError
from .problem import Problem
from .residuals import Residuals

_VEC = types.Array(types.float64, 1, "C", readonly=True)
_MAT = types.Array(types.float64, 2, "C", readonly=True)
_SIGNATURE = types.UniTuple(types.float64, 7)(
    _MAT, _VEC, _MAT, _VEC, _MAT, _VEC, _VEC, _VEC, _VEC, _VEC, _VEC, _VEC, types.int64
)

#: ``flags`` bits of :func:`_kernel`.
HAS_LB, HAS_UB, DUALS = 1, 2, 4

_NO_VECTOR = np.zeros(0)
_NO_MATRIX = np.zeros((0, 0))
for _array in (_NO_VECTOR, _NO_MATRIX):
    _array.flags.writeable = False


@njit(inline="always")
def _max(a: float, b: float) -> float:
    """``max(a, b)`` that propagates NaN from either side."""
    return a if (a >= b or a != a) else b


@njit(inline="always")
def _weight(slack: float) -> float:
    """``|slack|``, or 1 for an infinite slack (complementarity of an inactive row)."""
    return abs(slack) if math.isfinite(slack) else 1.0


@njit(cache=True)
def _primal(
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    x: np.ndarray,
    flags: int,
) -> tuple[float, float, float, float]:
    """``(x_finite, equality, inequality, bounds)``."""
    n = x.shape[0]
    finite = 1.0
    for j in range(n):
        if not math.isfinite(x[j]):
            finite = 0.0
    equality = inequality = bounds = 0.0
    for i in range(A.shape[0]):
        r = -b[i]
        for j in range(n):
            r += A[i, j] * x[j]
        equality = _max(equality, abs(r))
    for i in range(G.shape[0]):  # slack h - G x
        s = 0.0
        for j in range(n):
            s += G[i, j] * x[j]
        inequality = _max(inequality, -(h[i] - s))
    for j in range(n):
        if flags & HAS_UB:
            bounds = _max(bounds, -(ub[j] - x[j]))
        if flags & HAS_LB:
            bounds = _max(bounds, -(x[j] - lb[j]))
    return finite, equality, inequality, bounds


@njit(cache=True)
def _dual(
    A: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray,
    z_box: np.ndarray,
    flags: int,
    grad: np.ndarray,
) -> tuple[float, float]:
    """``(stationarity, complementarity)``, ``grad`` holding ``P x + q`` on entry."""
    n = x.shape[0]
    complementarity = 0.0
    for i in range(A.shape[0]):
        for j in range(n):
            grad[j] += y[i] * A[i, j]
    for i in range(G.shape[0]):
        s = 0.0
        for j in range(n):
            grad[j] += z[i] * G[i, j]
            s += G[i, j] * x[j]
        complementarity = _max(complementarity, -z[i])
        complementarity = _max(complementarity, max(z[i], 0.0) * _weight(h[i] - s))
    if flags & (HAS_LB | HAS_UB):
        for j in range(n):
            zj = z_box[j]
            grad[j] += zj
            if flags & HAS_UB:  # z_box > 0 pairs with the upper slack
                complementarity = _max(complementarity, max(zj, 0.0) * _weight(ub[j] - x[j]))
            else:  # a multiplier on a missing bound is all error
                complementarity = _max(complementarity, zj)
            if flags & HAS_LB:  # z_box < 0 pairs with the lower slack
                complementarity = _max(complementarity, max(-zj, 0.0) * _weight(x[j] - lb[j]))
            else:
                complementarity = _max(complementarity, -zj)
    stationarity = 0.0
    for j in range(n):
        stationarity = _max(stationarity, abs(grad[j]))
    return stationarity, complementarity


@njit(_SIGNATURE, cache=True)
def _kernel(
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
) -> tuple[float, float, float, float, float, float, float]:
    """``(x_finite, equality, inequality, bounds, stationarity, complementarity, scale)``.

    ``x_finite`` is 1.0 or 0.0; stationarity and complementarity are NaN placeholders
    unless ``flags & DUALS`` (every multiplier the problem needs is given).
    """
    finite, equality, inequality, bounds = _primal(A, b, G, h, lb, ub, x, flags)
    n = x.shape[0]
    grad = np.empty(n)
    scale = 0.0
    for j in range(n):
        s = 0.0
        for k in range(n):
            s += P[j, k] * x[k]
        scale = _max(_max(scale, abs(s)), abs(q[j]))
        grad[j] = s + q[j]
    if not flags & DUALS:
        return finite, equality, inequality, bounds, np.nan, np.nan, scale
    stationarity, complementarity = _dual(A, G, h, lb, ub, x, y, z, z_box, flags, grad)
    return finite, equality, inequality, bounds, stationarity, complementarity, scale


def _multiplier(name: str, value: np.ndarray | None, size: int) -> np.ndarray | None:
    """``value`` as a float64 C-contiguous vector of shape ``(size,)`` (None if absent)."""
    if value is None:
        return None
    if not (type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous):
        value = np.ascontiguousarray(value, dtype=np.float64)
    if value.shape != (size,):
        raise ProblemShapeError(f"{name}: expected shape ({size},), got {value.shape}")
    return value


def evaluate(
    problem: Problem,
    x: np.ndarray,
    y: np.ndarray | None = None,
    z: np.ndarray | None = None,
    z_box: np.ndarray | None = None,
) -> tuple[bool, tuple[float, float, float, float, float, float, float]]:
    """Raw kernel output for ``problem`` at ``x`` (shape ``(n,)``, float64, C-contiguous).

    Returns
    -------
    bool
        Whether every multiplier the problem needs is given (else the dual residuals are
        NaN placeholders).
    tuple of float
        ``(x_finite, equality, inequality, bounds, stationarity, complementarity, scale)``
        with ``x_finite`` 1.0 or 0.0 (see :func:`kkt_residuals` for the others).

    Raises
    ------
    ProblemShapeError
        If a needed multiplier has the wrong shape.
    """
    p = problem
    A, G, lb, ub = p.A, p.G, p.lb, p.ub
    flags = (HAS_LB if lb is not None else 0) | (HAS_UB if ub is not None else 0)
    duals = True
    if A is not None:
        y = _multiplier("y", y, A.shape[0])
        duals = y is not None
    if G is not None:
        z = _multiplier("z", z, G.shape[0])
        duals = duals and z is not None
    if flags:
        z_box = _multiplier("z_box", z_box, x.shape[0])
        duals = duals and z_box is not None
    values = _kernel(
        p.P,
        p.q,
        _NO_MATRIX if A is None else A,
        _NO_VECTOR if A is None else p.b,
        _NO_MATRIX if G is None else G,
        _NO_VECTOR if G is None else p.h,
        _NO_VECTOR if lb is None else lb,
        _NO_VECTOR if ub is None else ub,
        x,
        _NO_VECTOR if A is None or y is None else y,
        _NO_VECTOR if G is None or z is None else z,
        _NO_VECTOR if not flags or z_box is None else z_box,
        flags | (DUALS if duals else 0),
    )
    return duals, values


def kkt_residuals(
    problem: Problem,
    x: np.ndarray,
    y: np.ndarray | None = None,
    z: np.ndarray | None = None,
    z_box: np.ndarray | None = None,
) -> tuple[Residuals, float]:
    """Compiled :func:`solvers.residuals.kkt_residuals`: residuals and gradient scale.

    Parameters
    ----------
    problem : Problem
        The QP (regular or :meth:`~solvers.Problem.trusted`).
    x : ndarray, shape (n,)
        Primal candidate (not checked for finiteness here).
    y, z, z_box : ndarray, optional
        Multipliers in the package sign convention; converted to float64 if needed.

    Returns
    -------
    Residuals
        Stationarity and complementarity are None unless every needed multiplier is given.
    float
        The gradient scale ``max(||P x||_inf, ||q||_inf)``.

    Raises
    ------
    ProblemShapeError
        If ``x`` or a needed multiplier has the wrong shape.
    """
    point = _multiplier("x", x, problem.n)
    assert point is not None
    duals, (_, equality, inequality, bounds, stat, comp, scale) = evaluate(
        problem, point, y, z, z_box
    )
    if not duals:
        return Residuals(equality, inequality, bounds), scale
    return Residuals(equality, inequality, bounds, stat, comp), scale
