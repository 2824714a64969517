"""Direct DAQP adapter using ``daqp.Model`` (setup once, ``update``, warm active set).

DAQP solves ``min 1/2 x^T H x + f^T x  s.t.  lower <= x[:ms] <= upper`` (simple
bounds, the first ``ms`` entries of ``lower``/``upper``) and
``lower <= M x <= upper`` for the rows of ``M = [G; A]``, equality rows flagged
with sense 5 (active + immutable). Bounds are native simple bounds, ``+-inf``
are passed as is. ``info['lam']`` is ordered ``[bounds, G rows, A rows]`` and
already follows the package sign convention.

Warm start: ``Model.update`` keeps the working set of the previous solve when
``sense`` is not passed, which is what this adapter relies on. ``initvals``
is only used on a cold set-up (``primal_start``); the Python ``update`` has no
way to pass a primal iterate.

Per-step cost: the stacked data ``H``, ``f``, ``[G; A]``, ``bupper``, ``blower`` live in
buffers allocated at set-up; an update copies the problem's arrays into them in place
(constant parts, e.g. ``-inf`` lower bounds of the ``G`` rows, are written once) and passes
``H`` only when ``P`` differs from the kept copy, so DAQP re-factors ``H`` only then.

API notes (daqp 0.11): ``Model.update`` silently ignores arrays whose shape
differs from the set-up (no error), hence the structure key; every array must
be writable (typed memoryviews reject read-only buffers), which the buffers are.
"""

from __future__ import annotations

from time import perf_counter
from typing import Any, ClassVar

import daqp
import numpy as np

from ._fast import refresh
from .problem import Problem
from .stateful import RawResult, StatefulBackend

#: DAQP exit flags, from DAQP's ``constants.h``.
EXIT_FLAGS = {
    2: "soft_optimal",
    1: "optimal",
    -1: "infeasible",
    -2: "cycle",
    -3: "unbounded",
    -4: "iterlimit",
    -5: "nonconvex",
    -6: "overdetermined_initial",
    -7: "timelimit",
}

_SENSE_EQUALITY = 5


class DaqpBackend(StatefulBackend):
    """DAQP dual active-set solver, warm-started from the previous working set.

    Parameters
    ----------
    tolerance : float, optional
        Primal residual tolerance of the check (default 1e-6).
    **settings
        ``daqp.Model.settings`` keys overriding :attr:`default_settings`.
    """

    name: str = "daqp"
    default_tolerance: ClassVar[float] = 1e-6
    default_settings: ClassVar[dict[str, Any]] = {"primal_tol": 1e-8}

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._model: Any = None
        self._ms = self._p = 0  # rows of simple bounds and of G in DAQP's stacking
        self._H = self._M = np.zeros((0, 0))
        self._f = self._upper = self._lower = np.zeros(0)

    @classmethod
    def known_settings(cls) -> set[str]:
        """Keys of ``daqp.Model().settings`` (DAQP itself ignores unknown keys)."""
        return set(daqp.Model().settings)

    def _release(self) -> None:
        self._model = None

    def _fill(self, problem: Problem) -> None:
        """Copy ``q``, ``G``, ``h``, ``A``, ``b``, ``lb``, ``ub`` into the set-up's buffers."""
        ms, p = self._ms, self._p
        self._f[:] = problem.q
        if problem.G is not None:
            self._M[:p] = problem.G
            self._upper[ms : ms + p] = problem.h
        if problem.A is not None:
            self._M[p:] = problem.A
            self._upper[ms + p :] = problem.b
            self._lower[ms + p :] = problem.b
        if problem.lb is not None:
            self._lower[:ms] = problem.lb
        if problem.ub is not None:
            self._upper[:ms] = problem.ub

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        n, p, m = problem.n, problem.n_in, problem.n_eq
        ms = n if problem.has_bounds else 0
        self._ms, self._p, rows = ms, p, ms + p + m
        self._H = np.array(problem.P)  # DAQP's H, and the reference that tells P changed
        self._f = np.empty(n)
        self._M = np.empty((p + m, n))
        self._upper, self._lower = np.full(rows, np.inf), np.full(rows, -np.inf)
        self._fill(problem)
        sense = np.zeros(rows, dtype=np.intc)
        sense[rows - m :] = _SENSE_EQUALITY
        model = daqp.Model()
        model.settings = dict(self.settings)
        start = perf_counter()
        flag, _ = model.setup(
            H=self._H,
            f=self._f,
            A=self._M,
            bupper=self._upper,
            blower=self._lower,
            sense=sense,
            primal_start=guess,
        )
        if flag < 0:
            return RawResult(None, f"setup failed: {EXIT_FLAGS.get(flag, flag)}")
        self._model = model
        return self._run(problem, start)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        self._fill(problem)
        H = self._H if refresh(problem.P, self._H) else None
        start = perf_counter()
        flag = self._model.update(H=H, f=self._f, A=self._M, bupper=self._upper, blower=self._lower)
        if flag < 0:
            return RawResult(None, f"update failed: {EXIT_FLAGS.get(flag, flag)}")
        return self._run(problem, start)

    def _run(self, problem: Problem, start: float) -> RawResult:
        x, _, flag, info = self._model.solve()
        solver_time = perf_counter() - start
        lam = info["lam"]
        ms, p = self._ms, self._p
        return RawResult(
            x=x,
            status=EXIT_FLAGS.get(flag, str(flag)),
            iterations=info["iterations"],
            y=lam[ms + p :],
            z=lam[ms : ms + p],
            z_box=lam[:ms] if ms else None,
            solver_time=solver_time,
        )
