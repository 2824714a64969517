r"""KKT residuals of a candidate QP solution, computed from the problem data only.

Multiplier sign convention (the one of ``qpsolvers``), used by every backend:

.. math::

    P x + q + A^T y + G^T z + z_{box} = 0, \qquad z \ge 0,

with ``z_box[i] <= 0`` when the lower bound of ``x[i]`` is active and
``z_box[i] >= 0`` when its upper bound is active.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .exceptions import ProblemShapeError
from .problem import Problem


@dataclass(frozen=True)
class Residuals:
    """Violation of each optimality condition, all in the infinity norm.

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
    """

    equality: float
    inequality: float
    bounds: float
    stationarity: float | None = None
    complementarity: float | None = None


def _multiplier(name: str, value: npt.ArrayLike | None, size: int) -> np.ndarray | None:
    if value is None:
        return None
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (size,):
        raise ProblemShapeError(f"{name}: expected shape ({size},), got {array.shape}")
    return array


def _slack_product(multiplier: np.ndarray, slack: np.ndarray, finite: bool) -> float:
    """Largest ``max(m, 0) * |slack|``; an infinite slack counts as 1."""
    if not multiplier.size:
        return 0.0
    if not finite:
        slack = np.where(np.isfinite(slack), slack, 1.0)
    return float((np.maximum(multiplier, 0.0) * np.abs(slack)).max())


def kkt_residuals(
    problem: Problem,
    x: np.ndarray,
    y: npt.ArrayLike | None = None,
    z: npt.ArrayLike | None = None,
    z_box: npt.ArrayLike | None = None,
) -> tuple[Residuals, float]:
    """:func:`residuals` plus the gradient scale ``max(||P x||_inf, ||q||_inf)``."""
    p = problem
    h_finite, lb_finite, ub_finite = p._finite
    equality = inequality = bounds = 0.0
    if p.A is not None and p.b is not None:
        equality = float(np.abs(p.A @ x - p.b).max())
    slack_in = p.h - p.G @ x if p.G is not None and p.h is not None else None
    if slack_in is not None:
        inequality = max(0.0, -float(slack_in.min()))
    slack_ub = None if p.ub is None else p.ub - x
    slack_lb = None if p.lb is None else x - p.lb
    if slack_ub is not None:
        bounds = max(bounds, -float(slack_ub.min()))
    if slack_lb is not None:
        bounds = max(bounds, -float(slack_lb.min()))
    Px = p.P @ x
    scale = max(float(np.abs(Px).max()), float(np.abs(p.q).max())) if p.n else 0.0

    y = _multiplier("y", y, p.n_eq) if p.n_eq else None
    z = _multiplier("z", z, p.n_in) if p.n_in else None
    z_box = _multiplier("z_box", z_box, p.n) if p.has_bounds else None
    if (p.n_eq and y is None) or (p.n_in and z is None) or (p.has_bounds and z_box is None):
        return Residuals(equality, inequality, bounds), scale

    gradient = Px + p.q
    complementarity = 0.0
    if p.A is not None and y is not None:
        gradient += y @ p.A
    if p.G is not None and z is not None and slack_in is not None:
        gradient += z @ p.G
        complementarity = max(-float(z.min()), _slack_product(z, slack_in, h_finite))
    if z_box is not None:
        gradient += z_box
        bound = _bound_complementarity(z_box, slack_lb, slack_ub, lb_finite, ub_finite)
        complementarity = max(complementarity, bound)
    stationarity = float(np.abs(gradient).max()) if p.n else 0.0
    return Residuals(equality, inequality, bounds, stationarity, max(complementarity, 0.0)), scale


def _bound_complementarity(
    z_box: np.ndarray,
    slack_lb: np.ndarray | None,
    slack_ub: np.ndarray | None,
    lb_finite: bool,
    ub_finite: bool,
) -> float:
    """Largest ``|z_box| * slack`` of the bounds, each sign paired with its side of the box."""
    if slack_ub is not None and slack_lb is not None and ub_finite and lb_finite:
        # z_box > 0 pairs with the upper slack, z_box < 0 with the lower one.
        paired = np.where(z_box > 0.0, slack_ub, slack_lb)
        return float(np.abs(z_box * paired).max())
    upper = _box_product(z_box, slack_ub, ub_finite)
    return max(upper, _box_product(-z_box, slack_lb, lb_finite))


def _box_product(multiplier: np.ndarray, slack: np.ndarray | None, finite: bool) -> float:
    """Complementarity of one side of the box; a multiplier on a missing bound is all error."""
    if slack is None:
        return float(multiplier.max())
    return _slack_product(multiplier, slack, finite)


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
        The QP the candidate solves.
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
        when every multiplier the problem needs is given.

    Raises
    ------
    ProblemShapeError
        If ``x`` or a needed multiplier has the wrong shape.
    """
    point = np.asarray(x, dtype=np.float64)
    if point.shape != (problem.n,):
        raise ProblemShapeError(f"x: expected shape ({problem.n},), got {point.shape}")
    return kkt_residuals(problem, point, y, z, z_box)[0]


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
        Empty when the solution is accepted.
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
