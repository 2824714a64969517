"""Result of a QP solve, judged by ``solvers`` itself rather than by the solver."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ._kkt import FINITE, MISFIT, MISFITTING
from .exceptions import ProblemShapeError, SolverError
from .kkt import evaluate, floats, quick
from .problem import Problem
from .refusal import refusal
from .residuals import ACCEPTABLE, Residuals, failed_checks, filled, passing


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
        about = (status, False, backend, tolerance, iterations, solve_time)
        times = {"retried": retried, "solver_time": solver_time}
        if x is None:
            message = f"{backend} returned no solution (status {status!r})"
            return cls(problem, None, *about, message=message, **times)
        try:
            answer = np.array(x, dtype=np.float64)
        except (TypeError, ValueError):
            message = f"{backend} said {status!r} but x is not a numeric array"
            return cls(problem, None, *about, message=message, **times)
        n = problem.q.shape[0]
        if answer.shape != (n,):
            message = f"{backend} said {status!r} but x has shape {answer.shape}, expected ({n},)"
            return cls(problem, answer, *about, message=message, **times)
        y, z, z_box = floats(y), floats(z), floats(z_box)
        values = quick(problem, answer, y, z, z_box)  # None: a misfit, which evaluate names
        try:
            values = values or evaluate(problem, answer, y, z, z_box)
        except ProblemShapeError:
            if math.isfinite(float(answer.sum())):
                raise
            values = _NOT_FINITE
        return _verdict(
            cls(problem, answer, *about, y, z, z_box, None, "", retried, solver_time), values
        )

    @classmethod
    def adopt(
        cls,
        problem: Problem,
        x: np.ndarray | None,
        *,
        backend: str,
        tolerance: float,
        status: str,
        iterations: int | None = None,
        y: np.ndarray | None = None,
        z: np.ndarray | None = None,
        z_box: np.ndarray | None = None,
        solver_time: float = 0.0,
    ) -> Solution:
        """:meth:`checked` for arrays handed over: ``x`` becomes the solution's, uncopied.

        For an adapter whose ``x`` is a fresh array that nothing else writes to, and whose
        multipliers the next solve does not overwrite. When ``x`` and the multipliers are
        float64 C-contiguous vectors of the problem's sizes, one compiled call checks them
        with no Python-side conversion; anything else goes through :meth:`checked` (which
        copies ``x``). Both give the same verdict, residuals and message.
        """
        values = None if x is None else quick(problem, x, y, z, z_box)
        return judged(
            problem,
            MISFITTING if values is None else values,
            x,
            y,
            z,
            z_box,
            backend,
            tolerance,
            status,
            iterations,
            solver_time,
        )

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
            problem,
            None,
            status,
            False,
            backend,
            tolerance,
            None,
            solve_time,
            message=message,
            retried=retried,
            solver_time=solver_time,
        )

    @property
    def refusal(self) -> str:
        """Why no answer was accepted, as one of :data:`REFUSALS` (``""`` when ``found``).

        Named from the solver's status word (``"infeasible"``, ``"iteration limit"``, ``"time
        limit"``), else ``"inaccurate"`` (an ``x`` that failed the check) or ``"no answer"``.
        The word only names the failure; whether an answer is accepted never depends on it.
        """
        return "" if self.found else refusal(self.status, self.x is not None)

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


#: Kernel values standing for a non-finite ``x`` whose multipliers could not be checked.
_NOT_FINITE = (0.0,) + (math.nan,) * 7


class SolverFailure(SolverError):
    """Raised by :meth:`Solution.require` when no acceptable solution was found.

    Attributes
    ----------
    solution : Solution
        The failed solution, with its status, residuals and message.
    """

    def __init__(self, solution: Solution) -> None:
        self.solution = solution
        super().__init__(solution.message or f"{solution.backend}: no solution found")


def _verdict(solution: Solution, values: tuple[float, ...]) -> Solution:
    """Set ``residuals``, ``found`` and (on rejection) ``message`` from kernel values."""
    tolerance = solution.tolerance
    residuals = passing(values, tolerance)
    if residuals is not None:
        solution.residuals, solution.found = residuals, True
        return solution
    code, equality, inequality, bounds, stationarity, complementarity, scale, gap = values
    if code == ACCEPTABLE:
        solution.residuals = filled(
            equality, inequality, bounds, stationarity, complementarity, gap
        )
    elif code == FINITE:
        solution.residuals = filled(equality, inequality, bounds)
    else:
        solution.y = solution.z = solution.z_box = None
        solution.message = f"{solution.backend} said {solution.status!r} but x is not finite"
        return solution
    solution.message = _Unmet(tolerance, scale)  # type: ignore[assignment]
    return solution


@dataclass(frozen=True)
class _Unmet:
    """A refused answer's message, formatted when it is read (a refusal is a step's common
    case on some scenes, its message seldom read): the checks its residuals failed."""

    tolerance: float
    scale: float


def _message(solution: Solution) -> str:
    text = solution.__dict__.get("_message", "")
    if isinstance(text, _Unmet):
        assert solution.residuals is not None
        failed = failed_checks(solution.residuals, text.tolerance, text.scale)
        text = f"{solution.backend} said {solution.status!r} but {', '.join(failed)}"
        solution.__dict__["_message"] = text
    return text  # type: ignore[no-any-return]


def _set_message(solution: Solution, text: str) -> None:
    solution.__dict__["_message"] = text


Solution.message = property(_message, _set_message)  # type: ignore[assignment]
"""Why the solution was rejected; empty when ``found`` (a refusal's is formatted when read)."""


def judged(
    problem: Problem,
    values: tuple[float, ...],
    x: np.ndarray,
    y: np.ndarray | None,
    z: np.ndarray | None,
    z_box: np.ndarray | None,
    backend: str,
    tolerance: float,
    status: str,
    iterations: int | None,
    solver_time: float,
) -> Solution:
    """:meth:`Solution.adopt` with the kernel ``values`` an adapter computed itself.

    For an adapter's per-step path: ``values`` come from :func:`solvers._kkt.kernel` or
    :func:`solvers._kkt.stacked` on ``problem``'s data with ``x``, ``y``, ``z``, ``z_box``
    (arrays handed over, kept uncopied). On :data:`~solvers._kkt.MISFIT` (e.g. a wrong
    shape) this is :meth:`Solution.checked`, which copies ``x`` and names the problem.
    """
    residuals = passing(values, tolerance)
    if residuals is None and values[0] == MISFIT:
        return Solution.checked(
            problem,
            x,
            backend=backend,
            tolerance=tolerance,
            status=status,
            iterations=iterations,
            y=y,
            z=z,
            z_box=z_box,
            solver_time=solver_time,
        )
    found = Solution(
        problem,
        x,
        status,
        residuals is not None,
        backend,
        tolerance,
        iterations,
        0.0,
        y,
        z,
        z_box,
        residuals,
        "",
        False,
        solver_time,
    )
    return found if residuals is not None else _verdict(found, values)
