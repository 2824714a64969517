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

API notes (daqp 0.11): ``Model.update`` silently ignores arrays whose shape
differs from the set-up (no error), hence the structure key; every array must
be writable (typed memoryviews reject read-only buffers), hence the copies.
"""

from __future__ import annotations

from typing import Any, ClassVar

import daqp
import numpy as np

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

    @classmethod
    def known_settings(cls) -> set[str]:
        """Keys of ``daqp.Model().settings`` (DAQP itself ignores unknown keys)."""
        return set(daqp.Model().settings)

    def _release(self) -> None:
        self._model = None

    @staticmethod
    def _data(problem: Problem) -> dict[str, np.ndarray]:
        n, p = problem.n, problem.n_in
        blocks = [m for m in (problem.G, problem.A) if m is not None]
        upper, lower = [], []
        if problem.has_bounds:
            upper.append(np.full(n, np.inf) if problem.ub is None else problem.ub)
            lower.append(np.full(n, -np.inf) if problem.lb is None else problem.lb)
        if problem.h is not None:
            upper.append(problem.h)
            lower.append(np.full(p, -np.inf))
        if problem.b is not None:
            upper.append(problem.b)
            lower.append(problem.b)
        return {
            "H": problem.P.copy(),
            "f": problem.q.copy(),
            "A": np.vstack(blocks) if blocks else np.zeros((0, n)),
            "bupper": np.concatenate(upper) if upper else np.zeros(0),
            "blower": np.concatenate(lower) if lower else np.zeros(0),
        }

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        data = self._data(problem)
        sense = np.zeros(data["bupper"].size, dtype=np.intc)
        sense[sense.size - problem.n_eq :] = _SENSE_EQUALITY
        model = daqp.Model()
        model.settings = dict(self.settings)
        flag, _ = model.setup(**data, sense=sense, primal_start=guess)
        if flag < 0:
            return RawResult(None, f"setup failed: {EXIT_FLAGS.get(flag, flag)}")
        self._model = model
        return self._run(problem)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        flag = self._model.update(**self._data(problem))
        if flag < 0:
            return RawResult(None, f"update failed: {EXIT_FLAGS.get(flag, flag)}")
        return self._run(problem)

    def _run(self, problem: Problem) -> RawResult:
        x, _, flag, info = self._model.solve()
        lam = np.asarray(info["lam"], dtype=np.float64)
        ms = problem.n if problem.has_bounds else 0
        return RawResult(
            x=np.asarray(x, dtype=np.float64),
            status=EXIT_FLAGS.get(flag, str(flag)),
            iterations=int(info["iterations"]),
            y=lam[ms + problem.n_in :],
            z=lam[ms : ms + problem.n_in],
            z_box=lam[:ms] if problem.has_bounds else None,
        )
