"""Result of a QP solve, judged by ``solvers`` itself rather than by the solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .exceptions import ProblemShapeError, SolverFailure
from .kkt import evaluate
from .problem import Problem
from .residuals import Residuals


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
        Wall-clock seconds of the whole ``backend.solve`` call: data update, solver,
        residual check (and a cold retry, if any).
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
    solver_time : float
        Of ``solve_time``, the seconds inside the solver library's own calls (set-up or
        data update, and solve; both attempts when ``retried``); 0.0 when the backend
        does not measure it.
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
    solver_time: float = 0.0

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
        solver_time: float = 0.0,
    ) -> Solution:
        """Build a solution and decide ``found`` from recomputed residuals.

        ``found`` is True iff ``x`` has shape (n,), is finite, its primal
        residuals are ``<= tolerance``, the multipliers of every constraint
        kind present are given, and stationarity and complementarity are
        ``<= tolerance * (1 + s)`` with ``s = max(||P x||_inf, ||q||_inf)``
        (they are in gradient units). Without multipliers a feasible but
        non-optimal ``x`` could not be told from the optimum, so it is refused.
        The residuals come from the compiled :mod:`solvers.kkt` kernel (one call,
        no NumPy temporaries); the message is only formatted on rejection.

        Parameters
        ----------
        problem : Problem
            The problem that was solved.
        x : ndarray, shape (n,), or None
            Primal answer of the solver (copied).
        backend, tolerance, status, iterations, solve_time, retried, solver_time
            Copied to the matching attributes.
        y, z, z_box : ndarray, optional
            Multipliers, already converted to the package sign convention; kept as
            given (not copied) when they are float64 C-contiguous arrays.

        Returns
        -------
        Solution
            With ``residuals`` and, on rejection, a one-line ``message``.
        """
        solution = cls(
            problem, None, status, False, backend, tolerance, iterations, solve_time,
            retried=retried, solver_time=solver_time,
        )  # fmt: skip
        if x is None:
            solution.message = f"{backend} returned no solution (status {status!r})"
            return solution
        try:
            answer = np.array(x, dtype=np.float64)
        except (TypeError, ValueError):
            solution.message = f"{backend} said {status!r} but x is not a numeric array"
            return solution
        solution.x = answer
        n = problem.q.shape[0]
        if answer.shape != (n,):
            solution.message = (
                f"{backend} said {status!r} but x has shape {answer.shape}, expected ({n},)"
            )
            return solution
        solution.y, solution.z, solution.z_box = _floats(y), _floats(z), _floats(z_box)
        try:
            duals, values = evaluate(problem, answer, solution.y, solution.z, solution.z_box)
        except ProblemShapeError:
            if math.isfinite(float(answer.sum())):
                raise
            values = (0.0,)
        if not values[0]:
            solution.y = solution.z = solution.z_box = None
            solution.message = f"{backend} said {status!r} but x is not finite"
            return solution
        solution._judge(duals, values)
        return solution

    def _judge(self, duals: bool, values: tuple[float, ...]) -> None:
        """Set ``residuals``, ``found`` and (on rejection) ``message`` from kernel values."""
        _, equality, inequality, bounds, stationarity, complementarity, scale = values
        tolerance = self.tolerance
        if not duals:
            self.residuals = Residuals(equality, inequality, bounds)
        else:
            self.residuals = Residuals(equality, inequality, bounds, stationarity, complementarity)
            dual_tol = tolerance * (1.0 + scale)
            if (
                equality <= tolerance
                and inequality <= tolerance
                and bounds <= tolerance
                and stationarity <= dual_tol
                and complementarity <= dual_tol
            ):
                self.found = True
                return
        failed = _failed_checks(self.residuals, tolerance, scale)
        self.message = f"{self.backend} said {self.status!r} but {', '.join(failed)}"

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
        solver_time: float = 0.0,
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
            solver_time=solver_time,
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


def _floats(value: npt.ArrayLike | None) -> np.ndarray | None:
    """A multiplier as a float64 C-contiguous array (as given if it already is), or None."""
    if value is None or (
        type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous
    ):
        return value  # type: ignore[return-value]
    return np.ascontiguousarray(value, dtype=np.float64)


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
