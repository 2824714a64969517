"""The per-step QP resolver: the paper's step plus every limit of the spec.

Each step first solves the QP with the hard tasks as equalities. If that fails (the tasks and
the limits conflict, or the backend's answer does not pass the residual check), it solves the
relaxed QP whose tasks carry a heavily weighted slack: the step then keeps every limit and
reports its task error (status ``"relaxed"``). If that fails too (the limits conflict among
themselves), the step brakes: the velocity closest to rest within the joint bounds (status
``"braking"``), which the exact check of the integrated motion then accepts, splits or fails.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike

import solvers
from dvqp import _validate
from dvqp.errors import BackendError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Bounds
from dvqp.resolution.qp import StepTerms, build_qp, limit_rows, step_terms
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Step, check_command


def make_backend(name: str) -> solvers.Backend:
    """A fresh QP backend by name (see :func:`solvers.available_backends`).

    Raises
    ------
    BackendError
        Unknown or not installed; the message lists the installed backends.
    """
    try:
        return solvers.make_backend(name)
    except solvers.SolverError as exc:
        raise BackendError(str(exc)) from exc


class QPResolver:
    """Resolves each step with a QP on a :mod:`solvers` backend.

    Parameters
    ----------
    spec
        Tasks, objective, limits and weights of the run.
    backend
        Backend name, e.g. ``"daqp"``, ``"osqp"``, ``"qpsolvers:quadprog"``, or a zero-argument
        callable returning a fresh :class:`solvers.Backend` (two are made: the strict and the
        relaxed problem keep their own warm starts).
    """

    holds_limits = True
    """Every limit of the spec is a hard constraint: runs are verified against them."""

    def __init__(self, spec: StepSpec, backend: str | Callable[[], solvers.Backend]) -> None:
        self.spec = spec
        factory = (lambda: make_backend(backend)) if isinstance(backend, str) else backend
        self.factory: Callable[[], solvers.Backend] = factory
        """Makes a fresh backend (the compiled step sets up its own)."""
        self._strict = factory()
        self._relaxed = factory()
        self.name = backend if isinstance(backend, str) else self._strict.name

    def reset(self) -> None:
        """Forget warm starts."""
        self._strict.reset()
        self._relaxed.reset()

    def resolve(self, state: KinematicState, command: ArrayLike, dt: float) -> Step:
        """One QP step (assembly + solve + check); see the module docstring."""
        start = time.perf_counter()
        cmd = check_command(command)
        dt = _validate.positive("dt", dt)
        parts = (step_terms(self.spec, state, cmd, dt), *limit_rows(self.spec, state, dt))
        box = parts[2]
        crossed = np.flatnonzero(box.lb > box.ub)
        if crossed.size:  # no velocity keeps every bound: nothing to solve
            i = int(crossed[0])
            message = (f"failed: the bounds on joint{i + 1}'s velocity cross "
                       f"({box.lb[i]:.4g} > {box.ub[i]:.4g} rad/s)")  # fmt: skip
            return Step(np.zeros(state.n), False, message, np.inf, time.perf_counter() - start)
        strict = build_qp(self.spec, state, cmd, dt, parts=parts)
        solution = self._strict.solve(strict.problem)
        solver_time, status = solution.solver_time, "optimal"
        if not solution.found:
            parts = (strict.terms, strict.inequalities, strict.bounds)
            solution = self._relaxed.solve(
                build_qp(self.spec, state, cmd, dt, relax=True, parts=parts).problem
            )
            solver_time, status = solver_time + solution.solver_time, "relaxed"
        if not solution.found or solution.x is None:
            return self._brake(strict.terms, strict.bounds, solution, start, solver_time)
        qdot = np.array(solution.x[: state.n])
        error = strict.terms.task_error(qdot)
        elapsed = time.perf_counter() - start
        return Step(qdot, True, status, error, elapsed, solution.iterations, solver_time)

    @staticmethod
    def _brake(
        terms: StepTerms, box: Bounds, solution: solvers.Solution, start: float, spent: float
    ) -> Step:
        """When even the relaxed QP has no answer (its inequalities conflict with the bounds,
        e.g. a damper whose distance turns a corner faster than the joints may accelerate):
        the step closest to rest inside the box, ``clip(0, lb, ub)``, the minimiser of
        ``½ Q̇ᵀ W Q̇`` over the box. The exact check of the integrated step then decides (a
        breach is split or fails). Status ``"braking"``; with crossed bounds, a failure."""
        elapsed = time.perf_counter() - start
        if np.any(box.lb > box.ub):
            message = f"failed: {solution.message}"
            return Step(np.zeros(box.lb.shape[0]), False, message, np.inf, elapsed,
                        solution.iterations, spent)  # fmt: skip
        qdot = np.clip(0.0, box.lb, box.ub)
        error = terms.task_error(qdot)
        return Step(qdot, True, "braking", error, elapsed, solution.iterations, spent)
