"""The per-step QP, assembled by pure functions so every backend gets the identical problem.

Decision variable ``x = Q̇`` (rad/s), or ``x = [Q̇; s]`` when the hard tasks are relaxed by a
slack ``s`` (task units per s)::

    minimise    ½ Q̇ᵀ (W + H) Q̇ + (c − g)ᵀ Q̇  (+ ½ ρ ‖s‖²)     g = λ ∂w/∂Q
    subject to  A Q̇ = b             (A Q̇ − s = b)            hard tasks (the tool's DV task)
                G Q̇ ≤ h                                      the limits' constraints
                lb ≤ Q̇ ≤ ub                                  the limits' bounds

``H, c`` are the soft tasks' costs (none in the paper). With no active inequality the KKT
conditions are exactly the weighted pseudoinverse step (:mod:`dvqp.resolution.pinv`), which
is built from the same :func:`step_terms`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Bounds, Constraint
from dvqp.resolution.spec import StepSpec
from solvers import Problem


@dataclass(frozen=True)
class StepTerms:
    """The unconstrained part of a step: metric, cost and hard-task equality.

    Attributes
    ----------
    weights : ndarray, shape (n,)
        Diagonal of ``W``.
    soft_hessian : ndarray, shape (n, n), or None
        ``H`` of the soft tasks (None without soft tasks).
    gradient : ndarray, shape (n,)
        ``g − c``: what the step follows (``g = λ ∂w/∂Q``, ``c`` from the soft tasks).
    A : ndarray, shape (m, n)
        Stacked Jacobians of the hard tasks.
    b : ndarray, shape (m,)
        Their wanted velocities.
    """

    weights: NDArray[np.float64]
    soft_hessian: NDArray[np.float64] | None
    gradient: NDArray[np.float64]
    A: NDArray[np.float64]
    b: NDArray[np.float64]

    def task_error(self, qdot: NDArray[np.float64]) -> float:
        """``‖A Q̇ − b‖∞`` of the hard tasks."""
        return float(np.abs(self.A @ qdot - self.b).max())


@dataclass(frozen=True)
class StepQP:
    """The QP of one step and what its rows mean.

    Attributes
    ----------
    problem : solvers.Problem
        The QP handed to a backend.
    terms : StepTerms
        Its unconstrained part.
    inequalities : Constraint
        The rows of ``problem.G`` over ``Q̇`` (their labels say what each holds).
    bounds : Bounds
        The box on ``Q̇``, rad/s.
    relaxed : bool
        The hard tasks carry a slack (the last m variables).
    """

    problem: Problem
    terms: StepTerms
    inequalities: Constraint
    bounds: Bounds
    relaxed: bool

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per inequality row, e.g. ``"link2/obstacle1"``."""
        return self.inequalities.labels


def step_terms(
    spec: StepSpec, state: KinematicState, command: NDArray[np.float64], dt: float
) -> StepTerms:
    """Evaluate the tasks and the objective of ``spec`` at ``state`` (pure)."""
    n = state.n
    hard_rows, hessian, gradient = [], None, spec.objective.scaled_gradient(state)
    for task in spec.tasks:
        rows = task.compute(state, command, dt)
        if task.hard:
            hard_rows.append(rows)
            continue
        h, c = rows.objective()
        hessian = h if hessian is None else hessian + h
        gradient = gradient - c
    if len(hard_rows) == 1:
        A, b = hard_rows[0].jacobian, hard_rows[0].velocity
    else:
        A = np.vstack([r.jacobian for r in hard_rows])
        b = np.concatenate([r.velocity for r in hard_rows])
    return StepTerms(spec.diagonal(n), hessian, gradient, A, b)


def limit_rows(spec: StepSpec, state: KinematicState, dt: float) -> tuple[Constraint, Bounds]:
    """The limits of ``spec`` at ``state``: stacked constraints and intersected bounds."""
    n = state.n
    parts: list[Constraint] = []
    box = Bounds(np.full(n, -np.inf), np.full(n, np.inf))
    first_box = True
    for limit in spec.limits:
        rows = limit.compute(state, dt)
        if isinstance(rows, Bounds):
            box = rows if first_box else box.intersect(rows)
            first_box = False
        else:
            parts.append(rows)
    return Constraint.stack(parts, n), box


def build_qp(
    spec: StepSpec,
    state: KinematicState,
    command: NDArray[np.float64],
    dt: float,
    *,
    relax: bool = False,
    parts: tuple[StepTerms, Constraint, Bounds] | None = None,
) -> StepQP:
    """Assemble the QP of one step (pure: no solver involved).

    Parameters
    ----------
    spec
        Tasks, objective, limits, weights.
    state
        Kinematics of this step.
    command
        The operator's tool DV velocity, shape (4,).
    dt
        Step, s.
    relax
        Add the slack ``s`` on the hard tasks.
    parts
        The terms, inequalities and bounds of this state if already computed (e.g. by the
        strict problem of the same step), so a relaxed retry does not evaluate them again.
    """
    if parts is None:
        parts = (step_terms(spec, state, command, dt), *limit_rows(spec, state, dt))
    terms, ineq, box = parts
    P = spec.hessian(state.n)
    if terms.soft_hessian is not None:
        P = P + terms.soft_hessian
    G, h = (ineq.G, ineq.h) if ineq.rows else (None, None)
    if not relax:
        problem = Problem(P=P, q=-terms.gradient, A=terms.A, b=terms.b, G=G, h=h,
                          lb=box.lb, ub=box.ub)  # fmt: skip
        return StepQP(problem, terms, ineq, box, relaxed=False)
    m = terms.A.shape[0]
    inf = np.full(m, np.inf)
    P_relaxed = np.zeros((state.n + m, state.n + m))
    P_relaxed[: state.n, : state.n] = P
    P_relaxed[state.n :, state.n :] = np.diag(np.full(m, spec.task_weight))
    problem = Problem(
        P=P_relaxed,
        q=np.concatenate([-terms.gradient, np.zeros(m)]),
        A=np.hstack([terms.A, -np.eye(m)]),
        b=terms.b,
        G=np.hstack([G, np.zeros((ineq.rows, m))]) if G is not None else None,
        h=h,
        lb=np.concatenate([box.lb, -inf]),
        ub=np.concatenate([box.ub, inf]),
    )
    return StepQP(problem, terms, ineq, box, relaxed=True)
