r"""KKT residuals of a candidate QP solution, computed from the problem data only.

Multiplier sign convention (the one of ``qpsolvers``), used by every backend:

.. math::

    P x + q + A^T y + G^T z + z_{box} = 0, \qquad z \ge 0,

with ``z_box[i] <= 0`` when the lower bound of ``x[i]`` is active and
``z_box[i] >= 0`` when its upper bound is active.

The values come from the compiled kernel of :mod:`solvers.kkt`, the package's one
implementation of the residuals; this module gives them their public form.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ._kkt import DUALS, FINITE
from .exceptions import ProblemShapeError
from .jit import njit
from .kkt import evaluate
from .problem import Problem


@dataclass(frozen=True)
class Residuals:
    """Violation of each optimality condition, all in the infinity norm.

    A residual computed from a NaN (in ``x``, a multiplier, or a trusted problem's data) is
    NaN, which no tolerance accepts.

    Attributes
    ----------
    equality : float
        ``max |A x - b|`` (0 without equalities).
    inequality : float
        ``max(G x - h, 0)`` (0 without inequalities).
    bounds : float
        ``max(lb - x, x - ub, 0)`` (0 without bounds).
    stationarity : float or None
        ``||P x + q + A^T y + G^T z + z_box||_inf``; None when a needed
        multiplier is missing.
    complementarity : float or None
        Largest ``|multiplier| * slack`` over inequality and bound rows, or
        wrong-signed multiplier ``max(-z, 0)``; a non-zero multiplier on a row
        with infinite slack counts as its own size. None without multipliers.
    duality_gap : float or None
        ``|xᵀPx + qᵀx + bᵀy + hᵀz + lbᵀz_box⁻ + ubᵀz_box⁺|`` over the rows and bounds with a
        finite right-hand side (qpbenchmark's duality gap; an infinite row's multiplier must
        be 0, which complementarity checks). None without multipliers.
    """

    equality: float
    inequality: float
    bounds: float
    stationarity: float | None = None
    complementarity: float | None = None
    duality_gap: float | None = None


def _multiplier(name: str, value: npt.ArrayLike | None, size: int) -> np.ndarray | None:
    """``value`` as a float64 array of shape ``(size,)``, None if absent."""
    if value is None:
        return None
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (size,):
        raise ProblemShapeError(f"{name}: expected shape ({size},), got {array.shape}")
    return array


def kkt_residuals(
    problem: Problem,
    x: npt.ArrayLike,
    y: npt.ArrayLike | None = None,
    z: npt.ArrayLike | None = None,
    z_box: npt.ArrayLike | None = None,
) -> tuple[Residuals, float]:
    """:func:`residuals` plus the gradient scale ``max(||P x||_inf, ||q||_inf)``.

    Returns
    -------
    Residuals
        Stationarity and complementarity are None unless every needed multiplier is given.
    float
        The gradient scale, which :func:`failed_checks` needs.

    Raises
    ------
    ProblemShapeError
        If ``x`` or a needed multiplier has the wrong shape, or a trusted problem's arrays
        do not fit ``x``.
    """
    p = problem
    point = np.asarray(x, dtype=np.float64)
    if point.shape != (p.n,):
        raise ProblemShapeError(f"x: expected shape ({p.n},), got {point.shape}")
    y = None if p.A is None else _multiplier("y", y, p.A.shape[0])
    z = None if p.G is None else _multiplier("z", z, p.G.shape[0])
    z_box = None if p.lb is None and p.ub is None else _multiplier("z_box", z_box, p.n)
    point = np.ascontiguousarray(point)  # for the kernel; evaluate sees to the multipliers
    code, equality, inequality, bounds, stat, comp, scale, gap = evaluate(p, point, y, z, z_box)
    if not int(code) & DUALS:
        return Residuals(equality, inequality, bounds), scale
    return Residuals(equality, inequality, bounds, stat, comp, gap), scale


def residuals(
    problem: Problem,
    x: npt.ArrayLike,
    y: npt.ArrayLike | None = None,
    z: npt.ArrayLike | None = None,
    z_box: npt.ArrayLike | None = None,
) -> Residuals:
    """Compute the KKT residuals of ``x`` (and multipliers) for ``problem``.

    Parameters
    ----------
    problem : Problem
        The QP the candidate solves (regular or :meth:`~solvers.Problem.trusted`).
    x : ndarray, shape (n,)
        Primal candidate.
    y : ndarray, shape (m,), optional
        Equality multipliers; needed for stationarity when ``m > 0``.
    z : ndarray, shape (p,), optional
        Inequality multipliers; needed for stationarity when ``p > 0``.
    z_box : ndarray, shape (n,), optional
        Bound multipliers; needed for stationarity when bounds are given.

    Returns
    -------
    Residuals
        Primal residuals always; ``stationarity`` and ``complementarity`` only
        when every multiplier the problem needs is given. A multiplier of a block the
        problem lacks is ignored.

    Raises
    ------
    ProblemShapeError
        If ``x`` or a needed multiplier has the wrong shape.
    """
    return kkt_residuals(problem, x, y, z, z_box)[0]


def failed_checks(res: Residuals, tolerance: float, scale: float) -> list[str]:
    """One phrase per residual above its tolerance, and one if optimality is unchecked.

    Parameters
    ----------
    res : Residuals
        The recomputed residuals.
    tolerance : float
        Absolute tolerance on the primal residuals.
    scale : float
        Gradient scale ``max(||P x||_inf, ||q||_inf)``; the dual residuals (stationarity,
        complementarity) are held to ``tolerance * (1 + scale)``.

    Returns
    -------
    list of str
        Empty when the solution is accepted; a NaN residual always fails.
    """
    dual_tol = tolerance * (1.0 + scale)
    checks = [
        ("equality", res.equality, tolerance),
        ("inequality", res.inequality, tolerance),
        ("bounds", res.bounds, tolerance),
        ("stationarity", res.stationarity, dual_tol),
        ("complementarity", res.complementarity, dual_tol),
    ]
    failed = [
        f"{name} residual {value:.1e} > tol {tol:.2g}"
        for name, value, tol in checks
        if value is not None and not value <= tol
    ]
    if res.stationarity is None:  # a feasible x is not yet an optimal one
        failed.append("no multipliers were returned, so optimality cannot be checked")
    return failed


#: The kernel's code of a finite ``x`` with every multiplier the problem needs.
ACCEPTABLE = FINITE | DUALS
_new = object.__new__


@njit
def accepts(values: tuple[float, ...], tolerance: float) -> bool:
    """Whether kernel ``values`` pass every check.

    ``values`` are :func:`solvers.kkt.evaluate`'s (or :func:`solvers._kkt.stacked`'s):
    they pass when ``x`` is finite, every needed multiplier was given, and every residual
    is within its tolerance (as :func:`failed_checks` has it); a NaN never passes. One rule,
    run by Python (:func:`passing`, the function itself) and by compiled code
    (:func:`solvers.daqp_c.solve_dropped`).
    """
    code, equality, inequality, bounds, stationarity, complementarity, scale, _ = values
    dual_tol = tolerance * (1.0 + scale)
    return (
        code == ACCEPTABLE
        and equality <= tolerance
        and inequality <= tolerance
        and bounds <= tolerance
        and stationarity <= dual_tol
        and complementarity <= dual_tol
    )


_accepts = accepts.py_func  # the same rule, run by Python: no compiled call


def passing(values: tuple[float, ...], tolerance: float) -> Residuals | None:
    """The residuals in kernel ``values`` if they pass every check (:func:`accepts`), else
    None."""
    if not _accepts(values, tolerance):
        return None
    _, equality, inequality, bounds, stationarity, complementarity, _, gap = values
    return filled(equality, inequality, bounds, stationarity, complementarity, gap)


def filled(
    equality: float,
    inequality: float,
    bounds: float,
    stationarity: float | None = None,
    complementarity: float | None = None,
    duality_gap: float | None = None,
) -> Residuals:
    """``Residuals(...)`` of these values, filled without the frozen dataclass's slower
    ``__init__`` (a per-solve path)."""
    residuals = _new(Residuals)
    residuals.__dict__.update(
        equality=equality,
        inequality=inequality,
        bounds=bounds,
        stationarity=stationarity,
        complementarity=complementarity,
        duality_gap=duality_gap,
    )
    return residuals
