"""Direct OSQP (>= 1.0) adapter: set up once, then ``update`` + warm start.

OSQP solves ``min 1/2 x^T P x + q^T x  s.t.  l <= M x <= u``. Rows of ``M`` are
``[A; G; I]`` (equalities with ``l = u = b``, inequalities with ``l = -inf``,
bounds as identity rows). ``P`` (upper triangle) and the ``A``/``G`` block use
a full dense sparsity pattern fixed at set-up, explicit zeros kept (a zero ``G``
row stays in the pattern), so an update only writes new values into buffers kept
from the set-up: ``M``'s CSC data is column-major with ``m + p (+ 1)`` entries per
column, i.e. a reshaped view in which ``A.T`` and ``G.T`` are copied; ``l``/``u``
are refilled in place, infinite entries clipped to ``OSQP_INFTY``. ``Px`` is passed
only when ``P`` differs from the kept copy. OSQP's dual ``y`` already follows the
package sign convention.

OSQP's default ``eps_abs = eps_rel = 1e-3`` leaves errors of ~5e-4 on ``x``;
the defaults here (1e-8, polishing on) reach ~1e-7 on ``x`` even when
polishing fails silently, which the residual check then catches anyway.

Limits (osqp 1.1.3): ADMM converges slowly when ``P`` spans many orders of
magnitude (e.g. a 1e6 slack weight beside unit joint weights); such problems
hit ``max_iter`` and come back with ``found=False``. The C library prints
some messages (``Polishing not needed ...``, non-convexity errors) to stdout
even with ``verbose=False``.
"""

from __future__ import annotations

from time import perf_counter
from typing import Any, ClassVar

import numpy as np
import osqp
import scipy.sparse as sp

from ._csc import CscPattern
from ._fast import refresh
from .problem import Problem
from .stateful import RawResult, StatefulBackend

#: OSQP's infinity: bounds beyond it are clipped (the Python wrapper would do it too).
INFINITY = 1e30


class OsqpBackend(StatefulBackend):
    """OSQP, warm-started through ``OSQP.update`` / ``OSQP.warm_start``.

    Parameters
    ----------
    tolerance : float, optional
        Primal residual tolerance of the check (default 1e-6).
    **settings
        OSQP settings overriding :attr:`default_settings`.
    """

    name: str = "osqp"
    default_tolerance: ClassVar[float] = 1e-6
    default_settings: ClassVar[dict[str, Any]] = {
        "verbose": False,
        "eps_abs": 1e-8,
        "eps_rel": 1e-8,
        "polishing": True,
        "max_iter": 20000,
    }
    required_settings: ClassVar[dict[str, Any]] = {"verbose": False}

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._solver: Any = None
        self._m = self._p = 0
        self._P = np.zeros((0, 0))  # copy of P at the last set-up/update
        self._p_take = np.zeros(0, dtype=np.int64)  # upper triangle of P, in CSC order
        self._Px, self._Ax = np.zeros(0), np.zeros(0)
        self._Ax_columns = np.zeros((0, 0))  # view of _Ax: one row per column of M
        self._lower, self._upper = np.zeros(0), np.zeros(0)

    @classmethod
    def known_settings(cls) -> set[str]:
        """OSQP settings fields, plus the names ``OSQP.update_settings`` translates."""
        fields = {k for k in vars(osqp.OSQP().ext.OSQPSettings) if not k.startswith("_")}
        return fields | {"solver_type", "cg_preconditioner", "polish", "warm_start"}

    def _release(self) -> None:
        self._solver = None

    def _fill(self, problem: Problem) -> None:
        """Copy the problem's constraint data into ``_Ax``, ``_lower``, ``_upper``."""
        m, p, cols = self._m, self._p, self._Ax_columns
        if problem.A is not None:
            cols[:, :m] = problem.A.T
            self._lower[:m] = self._upper[:m] = problem.b
        if problem.G is not None:
            cols[:, m : m + p] = problem.G.T
            np.minimum(problem.h, INFINITY, out=self._upper[m : m + p])
        if problem.lb is not None:
            np.maximum(problem.lb, -INFINITY, out=self._lower[m + p :])
        if problem.ub is not None:
            np.minimum(problem.ub, INFINITY, out=self._upper[m + p :])

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        n, m, p = problem.n, problem.n_eq, problem.n_in
        self._m, self._p = m, p
        bounds = problem.has_bounds
        rows = m + p + (n if bounds else 0)
        p_pattern = CscPattern.upper_triangle(n)
        self._P, self._p_take = np.array(problem.P), p_pattern.take
        self._Px = p_pattern.data(self._P)
        mask = np.ones((m + p, n), dtype=bool)
        if bounds:
            mask = np.vstack([mask, np.eye(n, dtype=bool)])
        m_pattern = CscPattern.from_mask(mask)  # column j: rows 0..m+p-1, then m+p+j
        self._Ax = np.zeros(m_pattern.indices.size)
        self._Ax_columns = self._Ax.reshape(n, -1)
        self._Ax_columns[:, m + p :] = 1.0  # the bound rows
        self._lower, self._upper = np.full(rows, -INFINITY), np.full(rows, INFINITY)
        self._fill(problem)
        constrained = rows > 0
        solver = osqp.OSQP()
        start = perf_counter()
        solver.setup(
            sp.csc_matrix((self._Px, p_pattern.indices, p_pattern.indptr), shape=(n, n)),
            problem.q,
            sp.csc_matrix((self._Ax, m_pattern.indices, m_pattern.indptr), shape=(rows, n))
            if constrained
            else None,
            self._lower if constrained else None,
            self._upper if constrained else None,
            **self.settings,
        )
        self._solver = solver
        if guess is not None:
            solver.warm_start(x=guess)
        return self._run(problem, start)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        self._fill(problem)
        changed = refresh(problem.P, self._P)
        if changed:
            np.take(self._P, self._p_take, out=self._Px, mode="clip")
        data: dict[str, np.ndarray] = {"q": problem.q}
        if self._lower.size:
            data.update(l=self._lower, u=self._upper, Ax=self._Ax)
        if changed:
            data["Px"] = self._Px
        solver = self._solver
        start = perf_counter()
        solver.update(**data)  # one call: one KKT re-factorisation
        if guess is not None:
            solver.warm_start(x=guess)
        return self._run(problem, start)

    def _run(self, problem: Problem, start: float) -> RawResult:
        result = self._solver.solve(raise_error=False)
        solver_time = perf_counter() - start
        m, p = self._m, self._p
        y = result.y
        return RawResult(
            x=result.x,
            status=str(result.info.status),
            iterations=int(result.info.iter),
            y=y[:m].copy(),
            z=y[m : m + p].copy(),
            z_box=y[m + p :].copy() if problem.has_bounds else None,
            solver_time=solver_time,
        )
