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
solve rebuilds.
"""

from __future__ import annotations

from collections.abc import Hashable
from typing import Any, ClassVar

import clarabel
import numpy as np

from ._csc import CscPattern
from .problem import Problem
from .stateful import RawResult, StatefulBackend


def _finite_masks(problem: Problem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Boolean masks of kept rows: finite ``h``, finite ``lb``, finite ``ub``."""
    none = np.zeros(problem.n, dtype=bool)
    h_ok = np.isfinite(problem.h) if problem.h is not None else np.zeros(0, dtype=bool)
    lb_ok = np.isfinite(problem.lb) if problem.lb is not None else none
    ub_ok = np.isfinite(problem.ub) if problem.ub is not None else none
    return h_ok, lb_ok, ub_ok


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

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._solver: Any = None
        self._updatable = False
        self._p_pattern: CscPattern | None = None
        self._m_pattern: CscPattern | None = None
        self._m_dense = np.zeros((0, 0))
        self._masks: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @classmethod
    def known_settings(cls) -> set[str]:
        """Attributes of ``clarabel.DefaultSettings``."""
        return {k for k in dir(clarabel.DefaultSettings()) if not k.startswith("_")}

    def _structure_of(self, problem: Problem) -> Hashable:
        h_ok, lb_ok, ub_ok = _finite_masks(problem)
        return (problem.n, problem.n_eq, h_ok.tobytes(), lb_ok.tobytes(), ub_ok.tobytes())

    def _release(self) -> None:
        self._solver = None

    def _fill(self, problem: Problem) -> np.ndarray:
        """Write ``A``/``G`` into the dense buffer; return the right-hand side."""
        assert self._masks is not None
        h_ok, lb_ok, ub_ok = self._masks
        m_eq, k = problem.n_eq, int(h_ok.sum())
        parts = []
        if problem.A is not None and problem.b is not None:
            self._m_dense[:m_eq] = problem.A
            parts.append(problem.b)
        if problem.G is not None and problem.h is not None:
            self._m_dense[m_eq : m_eq + k] = problem.G[h_ok]
            parts.append(problem.h[h_ok])
        if problem.lb is not None:
            parts.append(-problem.lb[lb_ok])
        if problem.ub is not None:
            parts.append(problem.ub[ub_ok])
        return np.concatenate(parts) if parts else np.zeros(0)

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        n = problem.n
        self._masks = h_ok, lb_ok, ub_ok = _finite_masks(problem)
        m_dense = problem.n_eq + int(h_ok.sum())
        eye = np.eye(n)
        self._m_dense = np.vstack([np.zeros((m_dense, n)), -eye[lb_ok], eye[ub_ok]])
        mask = np.vstack([np.ones((m_dense, n), dtype=bool), eye[lb_ok] != 0, eye[ub_ok] != 0])
        self._p_pattern = CscPattern.upper_triangle(n)
        self._m_pattern = CscPattern.from_mask(mask)
        rhs = self._fill(problem)
        cones = []
        if problem.n_eq:
            cones.append(clarabel.ZeroConeT(problem.n_eq))
        if rhs.size > problem.n_eq:
            cones.append(clarabel.NonnegativeConeT(rhs.size - problem.n_eq))
        settings = clarabel.DefaultSettings()
        for key, value in self.settings.items():
            setattr(settings, key, value)
        self._solver = clarabel.DefaultSolver(
            self._p_pattern.matrix(problem.P),
            problem.q,
            self._m_pattern.matrix(self._m_dense),
            rhs,
            cones,
            settings,
        )
        self._updatable = bool(self._solver.is_data_update_allowed())
        return self._run(problem)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        if not self._updatable:
            return self._setup(problem, guess)
        assert self._p_pattern is not None and self._m_pattern is not None
        rhs = self._fill(problem)
        self._solver.update(
            P=self._p_pattern.data(problem.P),
            q=problem.q,
            A=self._m_pattern.data(self._m_dense),
            b=rhs,
        )
        return self._run(problem)

    def _run(self, problem: Problem) -> RawResult:
        assert self._masks is not None
        result = self._solver.solve()
        h_ok, lb_ok, ub_ok = self._masks
        dual = np.asarray(result.z, dtype=np.float64)
        m_eq, k, k_lb = problem.n_eq, int(h_ok.sum()), int(lb_ok.sum())
        z = np.zeros(problem.n_in)
        z[h_ok] = dual[m_eq : m_eq + k]
        z_box = np.zeros(problem.n)
        z_box[lb_ok] -= dual[m_eq + k : m_eq + k + k_lb]
        z_box[ub_ok] += dual[m_eq + k + k_lb :]
        return RawResult(
            x=np.asarray(result.x, dtype=np.float64),
            status=str(result.status),
            iterations=int(result.iterations),
            y=dual[:m_eq],
            z=z,
            z_box=z_box if problem.has_bounds else None,
        )
