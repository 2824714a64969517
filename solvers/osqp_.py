"""Direct OSQP (>= 1.0) adapter: set up once, then ``update`` + warm start.

OSQP solves ``min 1/2 x^T P x + q^T x  s.t.  l <= M x <= u``. Rows of ``M`` are
``[A; G; I]`` (equalities with ``l = u = b``, inequalities with ``l = -inf``,
bounds as identity rows). ``P`` (upper triangle) and the ``A``/``G`` block use
a full dense sparsity pattern fixed at set-up, so an update only gathers the
new values into OSQP's data arrays; no scipy matrix is built per step. OSQP's
dual ``y`` already follows the package sign convention.

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

from typing import Any, ClassVar

import numpy as np
import osqp

from ._csc import CscPattern
from .problem import Problem
from .stateful import RawResult, StatefulBackend


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

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._solver: Any = None
        self._p_pattern: CscPattern | None = None
        self._m_pattern: CscPattern | None = None
        self._m_dense = np.zeros((0, 0))

    @classmethod
    def known_settings(cls) -> set[str]:
        """OSQP settings fields, plus the names ``OSQP.update_settings`` translates."""
        fields = {k for k in vars(osqp.OSQP().ext.OSQPSettings) if not k.startswith("_")}
        return fields | {"solver_type", "cg_preconditioner", "polish", "warm_start"}

    def _release(self) -> None:
        self._solver = None

    def _vectors(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        n, m_eq, p = problem.n, problem.n_eq, problem.n_in
        rows = m_eq + p + (n if problem.has_bounds else 0)
        lower, upper = np.empty(rows), np.empty(rows)
        if problem.b is not None:
            lower[:m_eq] = upper[:m_eq] = problem.b
        if problem.h is not None:
            lower[m_eq : m_eq + p] = -np.inf
            upper[m_eq : m_eq + p] = problem.h
        if problem.has_bounds:
            lower[m_eq + p :] = -np.inf if problem.lb is None else problem.lb
            upper[m_eq + p :] = np.inf if problem.ub is None else problem.ub
        return lower, upper

    def _fill(self, problem: Problem) -> None:
        if problem.A is not None:
            self._m_dense[: problem.n_eq] = problem.A
        if problem.G is not None:
            self._m_dense[problem.n_eq : problem.n_eq + problem.n_in] = problem.G

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        n, m_dense = problem.n, problem.n_eq + problem.n_in
        self._p_pattern = CscPattern.upper_triangle(n)
        mask = np.ones((m_dense, n), dtype=bool)
        self._m_dense = np.zeros((m_dense, n))
        if problem.has_bounds:
            mask = np.vstack([mask, np.eye(n, dtype=bool)])
            self._m_dense = np.vstack([self._m_dense, np.eye(n)])
        self._m_pattern = CscPattern.from_mask(mask)
        self._fill(problem)
        lower, upper = self._vectors(problem)
        constrained = lower.size > 0
        solver = osqp.OSQP()
        solver.setup(
            self._p_pattern.matrix(problem.P),
            problem.q,
            self._m_pattern.matrix(self._m_dense) if constrained else None,
            lower if constrained else None,
            upper if constrained else None,
            **self.settings,
        )
        self._solver = solver
        if guess is not None:
            solver.warm_start(x=guess)
        return self._run(problem)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        assert self._p_pattern is not None and self._m_pattern is not None
        self._fill(problem)
        lower, upper = self._vectors(problem)
        if lower.size:
            self._solver.update(
                q=problem.q,
                l=lower,
                u=upper,
                Px=self._p_pattern.data(problem.P),
                Ax=self._m_pattern.data(self._m_dense),
            )
        else:
            self._solver.update(q=problem.q, Px=self._p_pattern.data(problem.P))
        if guess is not None:
            self._solver.warm_start(x=guess)
        return self._run(problem)

    def _run(self, problem: Problem) -> RawResult:
        result = self._solver.solve(raise_error=False)
        m_eq, p = problem.n_eq, problem.n_in
        y = np.asarray(result.y)
        return RawResult(
            x=np.array(result.x),
            status=str(result.info.status),
            iterations=int(result.info.iter),
            y=y[:m_eq].copy(),
            z=y[m_eq : m_eq + p].copy(),
            z_box=y[m_eq + p :].copy() if problem.has_bounds else None,
        )
