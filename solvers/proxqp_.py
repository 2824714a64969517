"""Direct ProxQP adapter: ``proxqp.dense.QP`` initialised once, then ``update``.

ProxQP solves ``min 1/2 x^T H x + g^T x  s.t.  A x = b,  l <= C x <= u`` plus,
with ``box_constraints=True``, native bounds ``l_box <= x <= u_box``.
Inequalities use ``l = -inf``, ``u = h`` and infinite bounds are passed as is.
``results.z`` is ``[z (n_in), z_box (n)]`` and, with ``y``, already follows
the package sign convention.

Warm start: ``initial_guess = WARM_START_WITH_PREVIOUS_RESULT`` after
``update``. Known issue (proxsuite 0.8.0): after a large change of the data,
the warm-started solve can report ``PROXQP_PRIMAL_INFEASIBLE`` on a feasible
problem, or (at loose ``eps_abs``) ``PROXQP_SOLVED`` with an ``x`` off by more
than the tolerance. Lowering ``eps_primal_inf`` to 1e-10 removes most spurious
infeasibility verdicts; whatever remains fails the residual check and the base
class re-solves cold (``retried=True``).

Per step, the problem's arrays are passed as they are (ProxQP copies them and takes
read-only ones), the constant ``l = -inf`` and missing-bound vectors come from buffers
made at set-up, and ``H`` is passed only when ``P`` differs from the kept copy.
"""

from __future__ import annotations

from time import perf_counter
from typing import Any, ClassVar

import numpy as np
from proxsuite import proxqp

from ._fast import refresh
from .problem import Problem
from .stateful import RawResult, StatefulBackend


class ProxqpBackend(StatefulBackend):
    """ProxQP dense backend with native box constraints, warm-started.

    Parameters
    ----------
    tolerance : float, optional
        Primal residual tolerance of the check (default 1e-6).
    **settings
        ``proxqp.Settings`` attributes overriding :attr:`default_settings`.
    """

    name: str = "proxqp"
    default_tolerance: ClassVar[float] = 1e-6
    default_settings: ClassVar[dict[str, Any]] = {
        "eps_abs": 1e-9,
        "eps_rel": 0.0,
        # The default 1e-4 declares feasible problems infeasible (cold and,
        # more often, warm after a large data change) once eps_abs is tight.
        "eps_primal_inf": 1e-10,
        # ...so an infeasible problem is not declared so: it runs to the iteration caps,
        # ProxQP's 10 000 outer x 1 500 inner took up to 33 s a call (pipe-rack: 188 s). No
        # accepted solve on the bundled and bench scenes needs more than 725 outer iterations.
        "max_iter": 2000,
        "max_iter_in": 150,
        "verbose": False,
    }
    required_settings: ClassVar[dict[str, Any]] = {"verbose": False}

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._qp: Any = None
        self._P = np.zeros((0, 0))  # copy of P at the last set-up/update
        self._minus_inf, self._plus_inf = np.zeros(0), np.zeros(0)

    @classmethod
    def known_settings(cls) -> set[str]:
        """Attributes of ``proxqp.Settings``."""
        return {k for k in dir(proxqp.dense.QP(1, 0, 0).settings) if not k.startswith("_")}

    def _release(self) -> None:
        self._qp = None

    def _data(self, problem: Problem, H: np.ndarray | None) -> dict[str, np.ndarray | None]:
        n, minus_inf = problem.n, self._minus_inf
        data: dict[str, np.ndarray | None] = {
            "H": H,
            "g": problem.q,
            "A": problem.A,
            "b": problem.b,
            "C": problem.G,
            "l": None if problem.h is None else minus_inf[: problem.n_in],
            "u": problem.h,
        }
        if problem.lb is not None or problem.ub is not None:
            data["l_box"] = minus_inf[:n] if problem.lb is None else problem.lb
            data["u_box"] = self._plus_inf if problem.ub is None else problem.ub
        return data

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        qp = proxqp.dense.QP(
            problem.n, problem.n_eq, problem.n_in, box_constraints=problem.has_bounds
        )
        for key, value in self.settings.items():
            setattr(qp.settings, key, value)
        qp.settings.initial_guess = (
            proxqp.InitialGuess.EQUALITY_CONSTRAINED_INITIAL_GUESS
            if guess is None
            else proxqp.InitialGuess.WARM_START
        )
        self._P = np.array(problem.P)
        self._minus_inf = np.full(max(problem.n, problem.n_in), -np.inf)
        self._plus_inf = np.full(problem.n, np.inf)
        start = perf_counter()
        qp.init(**self._data(problem, self._P))
        if guess is None:
            qp.solve()
        else:
            qp.solve(guess, None, None)
        solver_time = perf_counter() - start
        qp.settings.initial_guess = proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
        self._qp = qp
        return self._result(problem, solver_time)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        data = self._data(problem, self._P if refresh(problem.P, self._P) else None)
        qp = self._qp
        start = perf_counter()
        qp.update(**data)
        if guess is None:
            qp.solve()
        else:
            qp.settings.initial_guess = proxqp.InitialGuess.WARM_START
            qp.solve(guess, None, None)
            qp.settings.initial_guess = proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT
        return self._result(problem, perf_counter() - start)

    def _result(self, problem: Problem, solver_time: float) -> RawResult:
        results = self._qp.results
        z = np.array(results.z, dtype=np.float64)
        p = problem.n_in
        return RawResult(
            x=np.array(results.x, dtype=np.float64),
            status=results.info.status.name,
            iterations=int(results.info.iter),
            y=np.array(results.y, dtype=np.float64),
            z=z[:p],
            z_box=z[p:] if problem.has_bounds else None,
            solver_time=solver_time,
        )
