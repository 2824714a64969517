"""An independent NumPy computation of the KKT residuals, the oracle of the compiled kernel.

Same formulas as ``solvers.residuals`` (see there for the sign convention and the meaning of
each residual), written with whole-array NumPy operations instead of the package's numba
loops. It is the reference the tests in ``tests/solvers/`` hold the package to (1e-12
relative), on data without NaN: here ``max(0.0, nan)`` can yield 0 where the package gives
NaN.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from solvers import Problem, Residuals
from solvers.residuals import _multiplier  # input checks, not the math under test


def _finite(v: np.ndarray | None) -> bool:
    """Whether ``v`` is absent or free of infinite entries (selects the simpler formulas)."""
    return v is None or bool(np.isfinite(v).all())


def _slack_product(multiplier: np.ndarray, slack: np.ndarray, finite: bool) -> float:
    """Largest ``max(m, 0) * |slack|``; an infinite slack counts as 1."""
    if not multiplier.size:
        return 0.0
    if not finite:
        slack = np.where(np.isfinite(slack), slack, 1.0)
    return float((np.maximum(multiplier, 0.0) * np.abs(slack)).max())


def _primal(
    p: Problem, x: np.ndarray
) -> tuple[float, float, float, np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    """``(equality, inequality, bounds, slack of G x <= h, slack to lb, slack to ub)``."""
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
    return equality, inequality, bounds, slack_in, slack_lb, slack_ub


def kkt_residuals(
    problem: Problem,
    x: np.ndarray,
    y: npt.ArrayLike | None = None,
    z: npt.ArrayLike | None = None,
    z_box: npt.ArrayLike | None = None,
) -> tuple[Residuals, float]:
    """The residuals of ``x`` and the gradient scale ``max(||P x||_inf, ||q||_inf)``."""
    p = problem
    equality, inequality, bounds, slack_in, slack_lb, slack_ub = _primal(p, x)
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
        complementarity = max(-float(z.min()), _slack_product(z, slack_in, _finite(p.h)))
    if z_box is not None:
        gradient += z_box
        bound = _bound_complementarity(z_box, slack_lb, slack_ub, _finite(p.lb), _finite(p.ub))
        complementarity = max(complementarity, bound)
    stationarity = float(np.abs(gradient).max()) if p.n else 0.0
    gap = _duality_gap(p, x, y, z, z_box)
    return Residuals(
        equality, inequality, bounds, stationarity, max(complementarity, 0.0), gap
    ), scale


def _duality_gap(
    p: Problem, x: np.ndarray, y: np.ndarray | None, z: np.ndarray | None, z_box: np.ndarray | None
) -> float:
    """qpbenchmark's gap over the rows and bounds with a finite right-hand side."""
    total = float(x @ p.P @ x + p.q @ x)
    if y is not None and p.b is not None:
        total += float(p.b @ y)
    if z is not None and p.h is not None:
        rows = np.isfinite(p.h)
        total += float(p.h[rows] @ z[rows])
    if z_box is not None:
        for bound, part in ((p.lb, np.minimum(z_box, 0.0)), (p.ub, np.maximum(z_box, 0.0))):
            if bound is not None:
                rows = np.isfinite(bound)
                total += float(bound[rows] @ part[rows])
    return abs(total)


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
