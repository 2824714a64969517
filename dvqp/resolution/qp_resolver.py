"""The per-step QP resolver: the paper's step plus joint, obstacle and height limits.

Each step first solves the QP with the task as a hard equality. If that fails (the task and
the limits conflict, or the backend's answer does not pass the residual check), it solves the
relaxed QP whose task carries a heavily weighted slack: the step then keeps every limit and
reports its task error (status ``"relaxed"``). Only if that fails too is the step a failure.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp import _validate
from dvqp.errors import BackendError
from dvqp.resolution.qp import StepConfig, build_step_qp
from dvqp.resolution.step import Step, step_inputs, task_error
from dvqp.kinematics.state import KinematicState


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
    config
        Limits, obstacles and weights of the run.
    backend
        Backend name, e.g. ``"daqp"``, ``"osqp"``, ``"qpsolvers:quadprog"``, or a zero-argument
        callable returning a fresh :class:`solvers.Backend` (two are made: the strict and the
        relaxed problem keep their own warm starts).
    """

    def __init__(self, config: StepConfig, backend: str | Callable[[], solvers.Backend]) -> None:
        self.config = config
        factory = (lambda: make_backend(backend)) if isinstance(backend, str) else backend
        self._strict = factory()
        self._relaxed = factory()
        self.name = backend if isinstance(backend, str) else self._strict.name

    def reset(self) -> None:
        """Forget warm starts."""
        self._strict.reset()
        self._relaxed.reset()

    def resolve(
        self,
        state: KinematicState,
        gradient: NDArray[np.float64],
        xdot: NDArray[np.float64],
        dt: float,
    ) -> Step:
        """One QP step (assembly + solve + check); see the module docstring."""
        start = time.perf_counter()
        n = state.n
        g, xd = step_inputs(state, gradient, xdot)
        step = _validate.positive("dt", dt)
        strict = build_step_qp(self.config, state, g, xd, step)
        solution = self._strict.solve(strict.problem)
        status = "optimal"
        if not solution.found:
            relaxed = build_step_qp(
                self.config, state, g, xd, step, relax_task=True,
                limits=(strict.inequalities, strict.bounds),
            )  # fmt: skip
            solution = self._relaxed.solve(relaxed.problem)
            status = "relaxed"
        iterations = solution.iterations
        if not solution.found or solution.x is None:
            elapsed = time.perf_counter() - start
            return Step(
                np.zeros(n), False, f"failed: {solution.message}", np.inf, elapsed, iterations
            )
        qdot = np.array(solution.x[:n])
        error = task_error(state, qdot, xd)
        elapsed = time.perf_counter() - start
        return Step(qdot, True, status, error, elapsed, iterations)
