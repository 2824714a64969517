"""Result of a QP solve, judged by ``solvers`` itself rather than by the solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .exceptions import SolverFailure
from .problem import Problem
from .residuals import Residuals, kkt_residuals


@dataclass(eq=False)
class Solution:
    """Outcome of :meth:`Backend.solve <solvers.Backend.solve>`.

    Attributes
    ----------
    problem : Problem
        The problem that was solved.
    x : ndarray, shape (n,), or None
        Primal solution returned by the solver (None if it gave none).
    status : str
        The solver's own status word, e.g. ``'solved'``, ``'PROXQP_SOLVED'``.
    found : bool
        Verdict of ``solvers``: True only if ``x`` is finite and every residual
        is within ``tolerance`` (see :meth:`checked`), whatever the status says.
    backend : str
        Name of the backend that produced the solution.
    tolerance : float
        Absolute tolerance on the primal residuals used for the verdict.
    iterations : int or None
        Solver iterations, when reported.
    solve_time : float
        Wall-clock seconds around the solver call, data update included.
    y : ndarray, shape (m,), or None
        Equality multipliers (sign convention in :mod:`solvers.residuals`).
    z : ndarray, shape (p,), or None
        Inequality multipliers, ``z >= 0``.
    z_box : ndarray, shape (n,), or None
        Bound multipliers, ``<= 0`` at an active lower and ``>= 0`` at an
        active upper bound.
    residuals : Residuals or None
        Residuals recomputed from the problem data (None without usable ``x``).
    message : str
        Why the solution was rejected; empty when ``found``.
    retried : bool
        True when a warm-started solve failed the check and was redone cold.
    """

    problem: Problem
    x: np.ndarray | None
    status: str
    found: bool
    backend: str
    tolerance: float
    iterations: int | None = None
    solve_time: float = 0.0
    y: np.ndarray | None = None
    z: np.ndarray | None = None
    z_box: np.ndarray | None = None
    residuals: Residuals | None = None
    message: str = ""
    retried: bool = False

    @classmethod
    def checked(
        cls,
        problem: Problem,
        x: npt.ArrayLike | None,
        *,
        backend: str,
        tolerance: float,
        status: str,
        iterations: int | None = None,
        solve_time: float = 0.0,
        y: npt.ArrayLike | None = None,
        z: npt.ArrayLike | None = None,
        z_box: npt.ArrayLike | None = None,
        retried: bool = False,
    ) -> Solution:
        """Build a solution and decide ``found`` from recomputed residuals.

        ``found`` is True iff ``x`` has shape (n,), is finite, its primal
        residuals are ``<= tolerance``, the multipliers of every constraint
        kind present are given, and stationarity and complementarity are
        ``<= tolerance * (1 + s)`` with ``s = max(||P x||_inf, ||q||_inf)``
        (they are in gradient units). Without multipliers a feasible but
        non-optimal ``x`` could not be told from the optimum, so it is refused.

        Parameters
        ----------
        problem : Problem
            The problem that was solved.
        x : ndarray, shape (n,), or None
            Primal answer of the solver.
        backend, tolerance, status, iterations, solve_time, retried
            Copied to the matching attributes.
        y, z, z_box : ndarray, optional
            Multipliers, already converted to the package sign convention.

        Returns
        -------
        Solution
            With ``residuals`` and, on rejection, a one-line ``message``.
        """
        solution = cls(
            problem=problem,
            x=None,
            status=status,
            found=False,
            backend=backend,
            tolerance=tolerance,
            iterations=iterations,
            solve_time=solve_time,
            retried=retried,
        )
        if x is None:
            solution.message = f"{backend} returned no solution (status {status!r})"
            return solution
        said = f"{backend} said {status!r} but"
        answer, flaw = _primal(problem, x)
        solution.x = answer
        if answer is None or flaw:
            solution.message = f"{said} {flaw}"
            return solution
        solution.y, solution.z, solution.z_box = (_floats(v) for v in (y, z, z_box))
        res, scale = kkt_residuals(problem, answer, solution.y, solution.z, solution.z_box)
        solution.residuals = res
        failed = _failed_checks(res, tolerance, scale)
        solution.found = not failed
        solution.message = f"{said} {', '.join(failed)}" if failed else ""
        return solution

    @classmethod
    def failure(
        cls,
        problem: Problem,
        *,
        backend: str,
        tolerance: float,
        status: str,
        message: str,
        solve_time: float = 0.0,
        retried: bool = False,
    ) -> Solution:
        """Build a solution for a solve that produced no answer at all (e.g. an exception)."""
        return cls(
            problem=problem,
            x=None,
            status=status,
            found=False,
            backend=backend,
            tolerance=tolerance,
            solve_time=solve_time,
            message=message,
            retried=retried,
        )

    def require(self) -> np.ndarray:
        """Return ``x`` if the solution was found, else raise :class:`SolverFailure`.

        Returns
        -------
        ndarray, shape (n,)
            The primal solution.

        Raises
        ------
        SolverFailure
            Carrying this solution, when ``found`` is False.
        """
        if not self.found or self.x is None:
            raise SolverFailure(self)
        return self.x


def _primal(problem: Problem, x: npt.ArrayLike) -> tuple[np.ndarray | None, str]:
    """``x`` as a float64 array (None if not numeric) and why it is unusable (``''`` if not)."""
    try:
        answer = np.array(x, dtype=np.float64)
    except (TypeError, ValueError):
        return None, "x is not a numeric array"
    if answer.shape != (problem.n,):
        return answer, f"x has shape {answer.shape}, expected ({problem.n},)"
    if not math.isfinite(float(answer.sum())):
        return answer, "x is not finite"
    return answer, ""


def _floats(value: npt.ArrayLike | None) -> np.ndarray | None:
    """A multiplier as a float64 array, or None."""
    return None if value is None else np.array(value, dtype=np.float64)


def _failed_checks(res: Residuals, tolerance: float, scale: float) -> list[str]:
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
