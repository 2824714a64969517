"""Direct Clarabel adapter: build once, then push new data with ``DefaultSolver.update``.

Clarabel solves ``min 1/2 x^T P x + q^T x  s.t.  M x + s = c,  s in K``. Rows
are ``[A; G_f; -I_lf; I_uf]`` with ``K = {0}^m x R_+^k``, where only rows with
a finite right-hand side are kept (``f``: finite ``h``, ``lf``/``uf``: finite
``lb``/``ub``). Which rows are finite is part of the structure key, so a row
becoming (in)finite triggers a rebuild. Multipliers: ``y = z[:m]``, ``z`` of
kept ``G`` rows, ``z_box = z_ub - z_lb`` (package sign convention).

Clarabel is an interior-point method and its Python API (0.11) has no warm
start, so ``initvals`` is ignored; the saving of the update path is the set-up
(equilibration, symbolic factorisation). Updates need ``presolve_enable=False``
(presolve drops rows); if ``is_data_update_allowed()`` is False anyway, every
solve rebuilds. Per step, the kept rows are gathered with index arrays fixed at
set-up into buffers (dense ``M`` block, CSC data, right-hand side) refilled in
place, and ``P`` is passed only when it differs from the kept copy.
"""

from __future__ import annotations

from collections.abc import Hashable
from time import perf_counter
from typing import Any, ClassVar

import clarabel
import numpy as np

from ._csc import CscPattern
from ._fast import refresh
from .problem import Problem
from .stateful import RawResult, StatefulBackend

_NONE = np.zeros(0, dtype=bool)


def _finite(v: np.ndarray | None) -> np.ndarray:
    """Mask of the finite entries of ``v`` (empty when ``v`` is absent)."""
    return _NONE if v is None else np.isfinite(v)


class ClarabelBackend(StatefulBackend):
    """Clarabel ``DefaultSolver`` reused through its data-update API.

    Parameters
    ----------
    tolerance : float, optional
        Primal residual tolerance of the check (default 1e-6).
    **settings
        ``clarabel.DefaultSettings`` attributes overriding :attr:`default_settings`.
    """

    name: str = "clarabel"
    default_tolerance: ClassVar[float] = 1e-6
    default_settings: ClassVar[dict[str, Any]] = {
        "verbose": False,
        "presolve_enable": False,  # presolve forbids data updates
        "tol_gap_abs": 1e-10,  # defaults (1e-8) leave ~1e-6 errors on x
        "tol_gap_rel": 1e-10,
        "tol_feas": 1e-10,
    }
    required_settings: ClassVar[dict[str, Any]] = {"verbose": False, "presolve_enable": False}

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._solver: Any = None
        self._updatable = False
        self._m = 0
        self._rows = self._lb_rows = self._ub_rows = np.zeros(0, dtype=np.intp)
        self._P = self._m_dense = np.zeros((0, 0))
        self._p_take = self._m_take = np.zeros(0, dtype=np.int64)
        self._Px = self._Ax = self._rhs = np.zeros(0)

    @classmethod
    def known_settings(cls) -> set[str]:
        """Attributes of ``clarabel.DefaultSettings``."""
        return {k for k in dir(clarabel.DefaultSettings()) if not k.startswith("_")}

    def _structure_of(self, problem: Problem) -> Hashable:
        A = problem.A
        return (
            problem.q.shape[0],
            0 if A is None else A.shape[0],
            _finite(problem.h).tobytes(),
            _finite(problem.lb).tobytes(),
            _finite(problem.ub).tobytes(),
        )

    def _release(self) -> None:
        self._solver = None

    def _fill(self, problem: Problem) -> None:
        """Gather the kept rows into ``_m_dense``/``_Ax`` and the right-hand side ``_rhs``."""
        m, k, k_lb = self._m, self._rows.size, self._lb_rows.size
        rhs = self._rhs
        if problem.A is not None:
            self._m_dense[:m] = problem.A
            rhs[:m] = problem.b
        # mode="clip" (indices are valid by construction) lets np.take write to ``out``
        # directly; the default mode="raise" buffers it.
        if k:
            np.take(problem.G, self._rows, axis=0, out=self._m_dense[m : m + k], mode="clip")
            np.take(problem.h, self._rows, out=rhs[m : m + k], mode="clip")
        if k_lb:
            lower = rhs[m + k : m + k + k_lb]
            np.take(problem.lb, self._lb_rows, out=lower, mode="clip")
            np.negative(lower, out=lower)
        if self._ub_rows.size:
            np.take(problem.ub, self._ub_rows, out=rhs[m + k + k_lb :], mode="clip")
        np.take(self._m_dense, self._m_take, out=self._Ax, mode="clip")

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        n, m = problem.n, problem.n_eq
        self._m = m
        self._rows, self._lb_rows, self._ub_rows = (
            np.flatnonzero(_finite(v)) for v in (problem.h, problem.lb, problem.ub)
        )
        m_dense = m + self._rows.size
        eye = np.eye(n)
        self._m_dense = np.vstack([np.zeros((m_dense, n)), -eye[self._lb_rows], eye[self._ub_rows]])
        mask = np.vstack([np.ones((m_dense, n), dtype=bool), self._m_dense[m_dense:] != 0])
        p_pattern = CscPattern.upper_triangle(n)
        m_pattern = CscPattern.from_mask(mask)
        self._P, self._p_take, self._m_take = np.array(problem.P), p_pattern.take, m_pattern.take
        self._Px = p_pattern.data(self._P)
        self._Ax = np.zeros(m_pattern.take.size)
        self._rhs = np.zeros(self._m_dense.shape[0])
        self._fill(problem)
        cones = []
        if m:
            cones.append(clarabel.ZeroConeT(m))
        if self._rhs.size > m:
            cones.append(clarabel.NonnegativeConeT(self._rhs.size - m))
        settings = clarabel.DefaultSettings()
        for key, value in self.settings.items():
            setattr(settings, key, value)
        start = perf_counter()
        self._solver = clarabel.DefaultSolver(
            p_pattern.matrix(self._P),
            problem.q,
            m_pattern.matrix(self._m_dense),
            self._rhs,
            cones,
            settings,
        )
        self._updatable = bool(self._solver.is_data_update_allowed())
        return self._run(problem, start)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        if not self._updatable:
            return self._setup(problem, guess)
        self._fill(problem)
        data: dict[str, np.ndarray] = {"q": problem.q, "A": self._Ax, "b": self._rhs}
        if refresh(problem.P, self._P):
            data["P"] = np.take(self._P, self._p_take, out=self._Px, mode="clip")
        start = perf_counter()
        self._solver.update(**data)
        return self._run(problem, start)

    def _run(self, problem: Problem, start: float) -> RawResult:
        result = self._solver.solve()
        solver_time = perf_counter() - start
        dual = np.asarray(result.z, dtype=np.float64)
        m, k, k_lb = self._m, self._rows.size, self._lb_rows.size
        z = np.zeros(problem.n_in)
        z[self._rows] = dual[m : m + k]
        z_box = np.zeros(problem.n)
        z_box[self._lb_rows] -= dual[m + k : m + k + k_lb]
        z_box[self._ub_rows] += dual[m + k + k_lb :]
        return RawResult(
            x=np.asarray(result.x, dtype=np.float64),
            status=str(result.status),
            iterations=int(result.iterations),
            y=dual[:m],
            z=z,
            z_box=z_box if problem.has_bounds else None,
            solver_time=solver_time,
        )
