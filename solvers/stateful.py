"""Base class of the stateful, warm-started adapters; subclass it to add a backend.

A backend only has to satisfy :class:`solvers.Backend`. :class:`StatefulBackend`
gives the direct adapters (``osqp``, ``clarabel``, ``daqp``, ``proxqp``) one
set-up / update / retry-cold policy: a subclass builds the solver in
:meth:`~StatefulBackend._setup`, pushes new data into it in
:meth:`~StatefulBackend._update`, and returns a :class:`RawResult`, which is then
judged by :meth:`Solution.checked <solvers.Solution.checked>` (or a :class:`Solution` it
judged itself, e.g. with :meth:`Solution.adopt <solvers.Solution.adopt>`).
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Hashable
from dataclasses import dataclass
from time import perf_counter
from typing import Any, ClassVar

import numpy as np

from .exceptions import ProblemShapeError, SolverError
from .problem import Problem
from .protocol import Backend
from .solution import Solution

#: Exceptions that reveal a bug in an adapter rather than a failed solve.
PROGRAMMING_ERRORS = (TypeError, AttributeError, NameError, ImportError, NotImplementedError)


@dataclass
class RawResult:
    """What a solver returned, multipliers already in the package sign convention.

    Attributes
    ----------
    x : ndarray, shape (n,), or None
        Primal answer (None if the solver gave none).
    status : str
        The solver's own status word.
    iterations : int or None
        Solver iterations, when reported.
    y : ndarray, shape (m,), or None
        Equality multipliers.
    z : ndarray, shape (p,), or None
        Inequality multipliers.
    z_box : ndarray, shape (n,), or None
        Bound multipliers (see :mod:`solvers.residuals` for the signs).
    solver_time : float or None
        Seconds inside the solver library's calls (set-up or update, and solve), if
        the adapter measured them; otherwise the whole adapter call is timed.
    """

    x: np.ndarray | None
    status: str
    iterations: int | None = None
    y: np.ndarray | None = None
    z: np.ndarray | None = None
    z_box: np.ndarray | None = None
    solver_time: float | None = None


def check_initvals(problem: Problem, initvals: np.ndarray | None) -> np.ndarray | None:
    """Return ``initvals`` as a float64 array of shape (n,), or None."""
    if initvals is None:
        return None
    guess = np.array(initvals, dtype=np.float64)
    if guess.shape != (problem.n,):
        raise ProblemShapeError(f"initvals: expected shape ({problem.n},), got {guess.shape}")
    return guess


def solve_guarded(
    backend: Backend, problem: Problem, run: Callable[..., RawResult | Solution], *args: Any
) -> Solution:
    """Call ``run(*args)`` and check its result; a solver exception becomes a failed Solution.

    Exceptions in :data:`PROGRAMMING_ERRORS` are adapter bugs and raise
    :class:`SolverError` instead. The solution's ``solver_time`` is the result's
    own ``solver_time`` when the adapter measured it, else the time of ``run``. A
    :class:`Solution` returned by ``run`` (an adapter that checked its answer itself, see
    :meth:`Solution.adopt <solvers.Solution.adopt>`) is returned as is. A solver that caught
    a SIGINT (Ctrl-C) and stopped, status ``interrupted`` (OSQP does), has the signal raised
    again, so that the program's own handler sees it (a KeyboardInterrupt by default).
    """
    start = perf_counter()
    try:
        raw = run(*args)
    except (SolverError, ProblemShapeError):  # adapter bug, or a problem that is not one
        raise
    except PROGRAMMING_ERRORS as exc:
        raise SolverError(f"{backend.name}: adapter error: {type(exc).__name__}: {exc}") from exc
    except Exception as exc:  # the solver library failed on this problem
        return Solution.failure(
            problem,
            backend=backend.name,
            tolerance=backend.tolerance,
            status="exception",
            message=f"{backend.name} raised {type(exc).__name__}: {exc}",
            solver_time=perf_counter() - start,
        )
    if "interrupt" in raw.status.lower():  # OSQP answers a Ctrl-C by stopping: the Ctrl-C
        signal.raise_signal(signal.SIGINT)  # was meant for the program, give it back to it
    if isinstance(raw, Solution):
        return raw
    solver_time = raw.solver_time
    return Solution.checked(
        problem,
        raw.x,
        backend=backend.name,
        tolerance=backend.tolerance,
        status=raw.status,
        iterations=raw.iterations,
        y=raw.y,
        z=raw.z,
        z_box=raw.z_box,
        solver_time=perf_counter() - start if solver_time is None else solver_time,
    )


class StatefulBackend:
    """Set up once, then update data and warm-start while the structure holds.

    Subclass it to add a backend: define ``name``, ``default_tolerance``,
    ``default_settings`` (and ``required_settings``, those of them the adapter needs whatever
    the tier), and implement :meth:`_setup` (cold: build the solver
    from scratch), :meth:`_update` (warm: push new data into the existing
    solver), both returning a :class:`RawResult` (or a :class:`Solution` they checked
    themselves, see :func:`solve_guarded`), and :meth:`_release`;
    override :meth:`_structure_of` when the solver needs more than the problem
    sizes to stay unchanged. If a warm answer fails :meth:`Solution.checked`,
    the problem is solved once more cold and the solution is flagged
    ``retried``.

    Parameters
    ----------
    tolerance : float, optional
        Absolute tolerance of the residual check (default ``default_tolerance``).
    solver_defaults : bool, optional
        Start from the solver's own factory defaults (with only :attr:`required_settings`),
        not from ``default_settings``: qpbenchmark's tiers (:mod:`solvers.tiers`).
    **settings
        Solver settings, merged over ``default_settings`` (or the factory defaults); unknown
        names raise :class:`SolverError`.
    """

    name: str
    default_tolerance: ClassVar[float]
    default_settings: ClassVar[dict[str, Any]]
    required_settings: ClassVar[dict[str, Any]] = {}
    """The settings of ``default_settings`` the adapter needs to work (quiet, data updates),
    kept with ``solver_defaults``; none of them about accuracy."""
    restarts: ClassVar[bool] = False
    """True if :meth:`_restart` solves cold within the set-up (no new set-up): then a cold
    retry, and the solve after a failed one, restart there instead of setting up again."""

    def __init__(
        self, *, tolerance: float | None = None, solver_defaults: bool = False, **settings: Any
    ) -> None:
        unknown = sorted(set(settings) - self.known_settings())
        if unknown:
            accepted = ", ".join(sorted(self.known_settings()))
            raise SolverError(
                f"{self.name}: unknown setting {', '.join(map(repr, unknown))} "
                f"(accepted: {accepted})"
            )
        self.tolerance = self.default_tolerance if tolerance is None else float(tolerance)
        base = self.required_settings if solver_defaults else self.default_settings
        self.settings: dict[str, Any] = {**base, **settings}
        self._structure: Hashable | None = None
        self._warm = False  # the last solve was accepted: the next may start from its state

    @classmethod
    def known_settings(cls) -> set[str]:
        """Setting names the solver accepts (checked at construction)."""
        return set(cls.default_settings)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(tolerance={self.tolerance:g})"

    def reset(self) -> None:
        """Forget the solver state; the next solve sets up from scratch."""
        self._structure = None
        self._warm = False
        self._release()

    def solve(self, problem: Problem, initvals: np.ndarray | None = None) -> Solution:
        """Solve ``problem``, warm-starting when its structure is unchanged.

        Parameters
        ----------
        problem : Problem
            The QP.
        initvals : ndarray, shape (n,), optional
            Primal guess, used where the solver supports it (otherwise the
            previous solution is the warm start).

        Returns
        -------
        Solution
            ``retried`` is True when the warm answer was rejected and redone cold.
        """
        start = perf_counter()
        guess = None if initvals is None else check_initvals(problem, initvals)
        structure = self._structure_of(problem)
        if structure == self._structure and self._warm:
            solution = solve_guarded(self, problem, self._update, problem, guess)
            return self.after_warm(problem, solution, start, guess)
        return self._settled(self._cold(problem, guess, structure), start)

    def after_warm(
        self,
        problem: Problem,
        solution: Solution,
        start: float,
        guess: np.ndarray | None = None,
    ) -> Solution:
        """Finish a solve of ``problem`` begun at ``start`` (``perf_counter``) whose warm attempt
        gave ``solution``: redone cold if refused (``retried``)."""
        if not solution.found:
            warm_time = solution.solver_time
            solution = self._cold(problem, guess, self._structure)
            solution.retried = True
            solution.solver_time += warm_time
        return self._settled(solution, start)

    def _settled(self, solution: Solution, start: float) -> Solution:
        """The solve's last word: the next may start warm only from an accepted answer."""
        self._warm = solution.found
        if not solution.found and (not self.restarts or solution.status == "exception"):
            self.reset()  # a solver that raised may be left in any state: set up anew
        solution.solve_time = perf_counter() - start
        return solution

    def _cold(self, problem: Problem, guess: np.ndarray | None, structure: Hashable) -> Solution:
        """Solve ``problem`` from a cold start: restarted within the kept set-up
        (:attr:`restarts`), or with the solver dropped and set up anew."""
        if self.restarts and structure == self._structure:
            return solve_guarded(self, problem, self._restart, problem, guess)
        self._structure = None
        self._release()
        solution = solve_guarded(self, problem, self._setup, problem, guess)
        self._structure = structure
        return solution

    def _structure_of(self, problem: Problem) -> Hashable:
        """Key that must be equal between two problems for a data update.

        The default is ``(n, n_eq, n_in, lb given, ub given)``, read straight from the
        array shapes (no property calls: this runs on every solve).
        """
        A, G = problem.A, problem.G
        return (
            problem.q.shape[0],
            0 if A is None else A.shape[0],
            0 if G is None else G.shape[0],
            problem.lb is not None,
            problem.ub is not None,
        )

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        """Build the solver for ``problem`` from scratch and solve (cold start)."""
        raise NotImplementedError

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        """Push ``problem``'s data into the existing solver and solve (warm start)."""
        raise NotImplementedError

    def _restart(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        """Push ``problem``'s data into the existing solver and solve from a cold start (no
        state of earlier solves kept); only called when :attr:`restarts` is True."""
        raise NotImplementedError

    def _release(self) -> None:
        """Drop the solver object (called before a cold set-up and on reset)."""
