"""Generic, stateless adapter for any solver installed behind ``qpsolvers``.

Each solve builds a ``qpsolvers.Problem`` and calls ``qpsolvers.solve_problem``
(``initvals`` passed through). Rows of ``G`` with ``h = +inf`` are dropped
before the call and get a zero multiplier back. Matrices go as CSC to solvers
that only take sparse input. ``qpsolvers`` already returns multipliers in the
package sign convention.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections.abc import Iterator
from time import perf_counter
from typing import Any

import numpy as np
import qpsolvers
import scipy.sparse as sp

from .problem import Problem
from .solution import Solution
from .stateful import RawResult, check_initvals, solve_guarded

#: Settings that push each solver to ~1e-7 accuracy on ``x`` (defaults are looser).
SETTINGS: dict[str, dict[str, Any]] = {
    "clarabel": {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10},
    "daqp": {"primal_tol": 1e-8},
    "highs": {"primal_feasibility_tolerance": 1e-9, "dual_feasibility_tolerance": 1e-9},
    "osqp": {
        "eps_abs": 1e-8,
        "eps_rel": 1e-8,
        "polishing": True,
        "max_iter": 20000,
        "raise_error": False,  # also silences osqp's PendingDeprecationWarning
    },
    "piqp": {"eps_abs": 1e-10, "eps_rel": 0.0},
    # proxqp.dense.solve takes no eps_primal_inf: this path keeps proxsuite's 1e-4 and
    # can call a feasible problem infeasible (the direct adapter lowers it).
    "proxqp": {"eps_abs": 1e-9, "eps_rel": 0.0, "max_iter": 2000},  # as proxqp_.py caps it
}

#: Of :data:`SETTINGS`, those kept whatever the tier (``solver_defaults``): none about accuracy.
REQUIRED: dict[str, dict[str, Any]] = {
    "osqp": {"raise_error": False},  # a failed solve as a status, not an exception
}

#: Primal residual tolerance of the check, per solver (also the accuracy on ``x``
#: expected). All solvers below reach <= 3e-7 on ``x`` with the settings above on
#: dvqp-sized problems (n ~ 13-20; measured with qpsolvers 4.13): active-set
#: solvers (daqp, quadprog) are exact, the others converge to ~1e-8. Solvers not
#: listed get DEFAULT_TOLERANCE; override per backend with ``tolerance=``.
TOLERANCE: dict[str, float] = {
    "clarabel": 1e-6,
    "daqp": 1e-6,
    "highs": 1e-6,
    "osqp": 1e-6,
    "piqp": 1e-6,
    "proxqp": 1e-6,
    "quadprog": 1e-6,
}
DEFAULT_TOLERANCE = 1e-6

#: Solvers whose C library prints to standard output whatever their settings say (HiGHS
#: prints its banner when a ``Highs()`` object is created, before any option can be set).
CHATTY = frozenset({"highs"})


@contextlib.contextmanager
def _quiet_c_stdout() -> Iterator[None]:
    """Send file descriptor 1 to the null device for the duration (C-level prints)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _status(extras: dict[str, Any], found: bool | None) -> str:
    """The solver's own status word when ``qpsolvers`` keeps it, else found/not found."""
    status = extras.get("status", getattr(extras.get("info"), "status", None))
    if status is None:
        return "found" if found else "not found"
    return str(getattr(status, "name", status))


def _iterations(extras: dict[str, Any]) -> int | None:
    info = extras.get("info")
    for value in (getattr(info, "iter", None), extras.get("iterations")):
        if value is not None:
            return int(np.ravel(value)[0])
    return None


class QpsolversBackend:
    """Any ``qpsolvers`` solver behind the :class:`~solvers.Backend` interface.

    Parameters
    ----------
    solver : str
        A name in ``qpsolvers.available_solvers``.
    name : str, optional
        Registry name reported in solutions (default ``'qpsolvers:<solver>'``).
    tolerance : float, optional
        Primal residual tolerance of the check (default from :data:`TOLERANCE`).
    solver_defaults : bool, optional
        Start from the solver's factory defaults (with only :data:`REQUIRED`), as qpsolvers
        leaves them, not from :data:`SETTINGS`: qpbenchmark's tiers (:mod:`solvers.tiers`).
    **settings
        Solver settings overriding :data:`SETTINGS` (or the factory defaults).
    """

    def __init__(
        self,
        solver: str,
        *,
        name: str | None = None,
        tolerance: float | None = None,
        solver_defaults: bool = False,
        **settings: Any,
    ) -> None:
        self.solver = solver
        self.name = name or f"qpsolvers:{solver}"
        default = TOLERANCE.get(solver, DEFAULT_TOLERANCE)
        self.tolerance = default if tolerance is None else float(tolerance)
        base = (REQUIRED if solver_defaults else SETTINGS).get(solver, {})
        self.settings: dict[str, Any] = {**base, **settings}
        self._sparse = solver in qpsolvers.sparse_solvers and solver not in qpsolvers.dense_solvers

    def __repr__(self) -> str:
        return f"QpsolversBackend({self.solver!r}, tolerance={self.tolerance:g})"

    def reset(self) -> None:
        """Nothing to drop: every solve is independent."""

    def solve(self, problem: Problem, initvals: np.ndarray | None = None) -> Solution:
        """Solve ``problem`` with ``qpsolvers.solve_problem``.

        Parameters
        ----------
        problem : Problem
            The QP.
        initvals : ndarray, shape (n,), optional
            Primal warm-start guess, passed to the solver.

        Returns
        -------
        Solution
            Checked by :meth:`Solution.checked`.
        """
        start = perf_counter()
        guess = check_initvals(problem, initvals)
        solution = solve_guarded(self, problem, self._run, problem, guess)
        solution.solve_time = perf_counter() - start
        return solution

    def _run(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        # Writable copies: some solvers (quadprog, daqp) reject read-only buffers.
        A, b, lb, ub = (
            None if v is None else np.array(v)
            for v in (problem.A, problem.b, problem.lb, problem.ub)
        )
        keep = None if problem.h is None else np.isfinite(problem.h)
        G = None if problem.G is None else problem.G[keep]
        h = None if problem.h is None else problem.h[keep]
        P: Any = np.array(problem.P)
        if self._sparse:
            P, G, A = (None if m is None else sp.csc_matrix(m) for m in (P, G, A))
        qp = qpsolvers.Problem(P, np.array(problem.q), G, h, A, b, lb, ub)
        quiet = _quiet_c_stdout() if self.solver in CHATTY else contextlib.nullcontext()
        # qpsolvers warns of a failed solve (its status word says the same): kept off stderr
        with quiet, warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            started = perf_counter()
            result = qpsolvers.solve_problem(qp, self.solver, initvals=guess, **self.settings)
            solver_time = perf_counter() - started
        status = _status(result.extras, result.found)
        if caught and status in ("found", "not found"):  # the warning is all the solver said
            status = str(caught[-1].message)
        z = None
        if keep is not None and result.z is not None:
            z = np.zeros(problem.n_in)
            z[keep] = result.z
        return RawResult(
            x=result.x,
            status=status,
            iterations=_iterations(result.extras),
            y=result.y if problem.n_eq else None,
            z=z,
            z_box=result.z_box if problem.has_bounds else None,
            solver_time=solver_time,
        )
