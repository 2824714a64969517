r"""The compiled KKT residuals, as raw values: one numba kernel over a problem's arrays.

The only implementation of the residuals in the package: :func:`solvers.residuals` and
:meth:`Solution.checked <solvers.Solution.checked>` both go through it (the tests hold it to
an independent NumPy oracle to 1e-12 relative). ``+inf`` in ``h``/``lb``/``ub`` is handled
(an infinite slack counts as 1 in complementarity), and so are missing blocks and missing
multipliers. A NaN in the data, ``x`` or a multiplier (e.g. in a trusted problem's ``h``)
makes the residuals computed from it NaN, hence a failed check, never a 0 the way
``max(0.0, nan)`` would give; only in complementarity does a NaN slack weigh 1, as an
infinite one does (the primal residual of its row is NaN already).

The kernel (:func:`solvers._kkt.kernel`) has a single signature (read-only float64
C-contiguous arrays, which writable arrays also match), compiled at its first call and cached
on disk; missing blocks are passed as empty arrays. It checks every size itself (a misfit
returns :data:`~solvers._kkt.MISFIT` and reads nothing out of range), so :func:`quick` can
call it on arrays as they come: about 1 µs on a dvqp-sized QP.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ._fast import EMPTY_MATRIX, EMPTY_VECTOR
from ._kkt import HAS_BOX, HAS_LB, HAS_UB, HAS_Y, HAS_Z, MISFIT, kernel
from .exceptions import ProblemShapeError
from .problem import Problem


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
) -> tuple[float, float, float, float, float, float, float, float] | None:
    """Raw kernel output if every array fits as given, else None (then use :func:`evaluate`).

    Fits: ``x`` and the given multipliers are float64 C-contiguous vectors (any other dtype,
    layout or dimension makes the compiled call refuse them) of the sizes the problem needs.
    No Python-side check or conversion (the kernel checks the sizes itself).

    Returns
    -------
    tuple of float or None
        ``(code, equality, inequality, bounds, stationarity, complementarity, scale, gap)``,
        ``code`` holding the bits :data:`~solvers._kkt.FINITE` and :data:`~solvers._kkt.DUALS`.
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
) -> tuple[float, float, float, float, float, float, float, float]:
    """Raw kernel output for ``problem`` at ``x`` (shape ``(n,)``, float64, C-contiguous).

    Multipliers are converted to float64 C-contiguous arrays and checked first (a multiplier
    of a block the problem lacks is ignored).

    Returns
    -------
    tuple of float
        ``(code, equality, inequality, bounds, stationarity, complementarity, scale, gap)``:
        ``code`` holds the bits :data:`~solvers._kkt.FINITE` (``x`` is finite) and
        :data:`~solvers._kkt.DUALS` (every multiplier the problem needs is given; else the
        dual residuals are NaN placeholders); see :class:`~solvers.Residuals` for the others.

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
