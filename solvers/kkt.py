r"""Compiled KKT residuals: :func:`solvers.residuals.kkt_residuals` in one numba kernel.

Same formulas and scale as the NumPy reference in :mod:`solvers.residuals` (the tests hold
them to 1e-12 relative), including ``+inf`` in ``h``/``lb``/``ub`` (an infinite slack
counts as 1 in complementarity), missing blocks and missing multipliers. One difference,
on data the regular :class:`~solvers.Problem` rejects: a NaN anywhere (e.g. in a trusted
problem's ``h``) makes the affected residual NaN, hence a failed check, where the
reference's ``max(0.0, nan)`` can yield 0.

The kernel has a single eager signature (read-only float64 C-contiguous arrays, which
writable arrays also match), compiled once and cached on disk (``cache=True``); missing
blocks are passed as empty arrays. It checks every size itself (a misfit returns
:data:`MISFIT` and reads nothing out of range), so :func:`quick` can call it on arrays as
they come: about 1 µs on a dvqp-sized QP.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ._fast import EMPTY_MATRIX, EMPTY_VECTOR
from ._kkt import DUALS, HAS_BOX, HAS_LB, HAS_UB, HAS_Y, HAS_Z, MISFIT, kernel
from .exceptions import ProblemShapeError
from .problem import Problem
from .residuals import Residuals


def _multiplier(name: str, value: np.ndarray | None, size: int) -> np.ndarray | None:
    """``value`` as a float64 C-contiguous vector of shape ``(size,)`` (None if absent)."""
    if value is None:
        return None
    if not (type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous):
        value = np.ascontiguousarray(value, dtype=np.float64)
    if value.shape != (size,):
        raise ProblemShapeError(f"{name}: expected shape ({size},), got {value.shape}")
    return value


def floats(value: npt.ArrayLike | None) -> np.ndarray | None:
    """A multiplier as a float64 C-contiguous array (as given if it already is), or None."""
    if value is None or (
        type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous
    ):
        return value  # type: ignore[return-value]
    return np.ascontiguousarray(value, dtype=np.float64)


def quick(
    problem: Problem,
    x: np.ndarray,
    y: np.ndarray | None = None,
    z: np.ndarray | None = None,
    z_box: np.ndarray | None = None,
) -> tuple[float, float, float, float, float, float, float] | None:
    """Raw kernel output if every array fits as given, else None (then use :func:`evaluate`).

    Fits: ``x`` and the given multipliers are float64 C-contiguous vectors (any other dtype,
    layout or dimension makes the compiled call refuse them) of the sizes the problem needs.
    No Python-side check or conversion (the kernel checks the sizes itself).

    Returns
    -------
    tuple of float or None
        ``(code, equality, inequality, bounds, stationarity, complementarity, scale)``,
        ``code`` holding the bits :data:`FINITE` and :data:`DUALS`.
    """
    p = problem
    A, G, lb, ub = p.A, p.G, p.lb, p.ub
    try:
        values = kernel(
            p.P,
            p.q,
            EMPTY_MATRIX if A is None else A,
            EMPTY_VECTOR if A is None else p.b,
            EMPTY_MATRIX if G is None else G,
            EMPTY_VECTOR if G is None else p.h,
            EMPTY_VECTOR if lb is None else lb,
            EMPTY_VECTOR if ub is None else ub,
            x,
            EMPTY_VECTOR if y is None else y,
            EMPTY_VECTOR if z is None else z,
            EMPTY_VECTOR if z_box is None else z_box,
            (0 if lb is None else HAS_LB)
            | (0 if ub is None else HAS_UB)
            | (0 if y is None else HAS_Y)
            | (0 if z is None else HAS_Z)
            | (0 if z_box is None else HAS_BOX),
        )
    except TypeError:  # not float64 C-contiguous vectors (or None data of a bad problem)
        return None
    return None if values[0] == MISFIT else values


def evaluate(
    problem: Problem,
    x: np.ndarray,
    y: np.ndarray | None = None,
    z: np.ndarray | None = None,
    z_box: np.ndarray | None = None,
) -> tuple[float, float, float, float, float, float, float]:
    """Raw kernel output for ``problem`` at ``x`` (shape ``(n,)``, float64, C-contiguous).

    Multipliers are converted to float64 C-contiguous arrays and checked first (a multiplier
    of a block the problem lacks is ignored).

    Returns
    -------
    tuple of float
        ``(code, equality, inequality, bounds, stationarity, complementarity, scale)``:
        ``code`` holds the bits :data:`FINITE` (``x`` is finite) and :data:`DUALS` (every
        multiplier the problem needs is given; else the dual residuals are NaN
        placeholders); see :func:`kkt_residuals` for the others.

    Raises
    ------
    ProblemShapeError
        If a needed multiplier has the wrong shape, or the problem's own arrays do not fit
        ``x`` (possible only with a :meth:`~solvers.Problem.trusted` problem).
    """
    p = problem
    n = x.shape[0]
    y = None if p.A is None else _multiplier("y", y, p.A.shape[0])
    z = None if p.G is None else _multiplier("z", z, p.G.shape[0])
    z_box = None if p.lb is None and p.ub is None else _multiplier("z_box", z_box, n)
    values = quick(problem, x, y, z, z_box)
    if values is None:
        raise ProblemShapeError(
            f"problem: arrays do not fit x of shape ({n},) or are not float64 C-contiguous"
        )
    return values


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
    code, equality, inequality, bounds, stat, comp, scale = evaluate(problem, point, y, z, z_box)
    if not int(code) & DUALS:
        return Residuals(equality, inequality, bounds), scale
    return Residuals(equality, inequality, bounds, stat, comp), scale
