"""The per-step QP compiled: one fixed-structure problem over the plan's buffers.

:class:`CompiledQP` binds the limits' kernels to one :class:`solvers.Problem` whose arrays are
the plan's own buffers (``Problem.trusted``: built once, overwritten in place each step), so
the backend is set up once and then only updated. Its answer is still checked by the backend
layer from the problem data (:meth:`solvers.Solution.checked`), and every integrated step is
verified exactly by the engine. As :class:`~dvqp.resolution.qp_resolver.QPResolver`: when the
strict problem has no accepted answer, the relaxed problem (the hard tasks with a slack of
weight ``ρ``, its own backend and warm start) is solved; when that fails too, the step brakes
(``clip(0, lb, ub)``), and with crossed bounds it is handed back to the reference resolver,
which reports the failure.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit
from numpy.typing import NDArray

import solvers
from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.compiled.solve import Answer, open_box, scale
from dvqp.resolution.spec import StepSpec

Array = NDArray[np.float64]


@njit(cache=True)
def relaxed_data(A, G, cost, lb, ub, A_r, G_r, cost_r, lb_r, ub_r) -> None:  # type: ignore[no-untyped-def]
    """Copy the strict problem's per-step data into the relaxed one's ``Q̇`` columns."""
    n = cost.shape[0]
    A_r[:, :n] = A
    G_r[:, :n] = G
    cost_r[:n] = cost
    lb_r[:n] = lb
    ub_r[:n] = ub


@njit(cache=True)
def crossed(lb: Array, ub: Array) -> int:
    """The first index with ``lb > ub``, or −1."""
    for i in range(lb.shape[0]):
        if lb[i] > ub[i]:
            return i
    return -1


@njit(cache=True)
def braking(lb: Array, ub: Array, out: Array) -> bool:
    """``out = clip(0, lb, ub)``: the step closest to rest in the box; False if it is empty."""
    for i in range(lb.shape[0]):
        if lb[i] > ub[i]:
            return False
        out[i] = min(max(0.0, lb[i]), ub[i])
    return True


class CompiledQP:
    """The per-step QP of :mod:`dvqp.resolution.qp` on fixed buffers (see the module docstring).

    Parameters
    ----------
    spec, plan
        The run's spec and plan (finalised: its stacked arrays exist).
    factory
        Makes a backend (two: the strict and the relaxed problem keep their own warm starts).
    rows
        The limits' kernels (bound here).
    gain
        ``λ``.
    """

    solves_in_prepare = False
    """:attr:`kernels` only assemble the QP; :meth:`solve` calls the backend."""

    def __init__(
        self, spec: StepSpec, plan: StepPlan, factory: Callable[[], solvers.Backend],
        rows: list[Kernel], gain: float,
    ) -> None:  # fmt: skip
        self.plan = plan
        plan.finalize()
        n, st = plan.n, plan.stacked
        m, p = st["A"].shape[0], st["G"].shape[0]
        self.cost = np.zeros(n)
        P = np.diag(spec.diagonal(n))
        self.problem = solvers.Problem.trusted(
            P=P, q=self.cost, A=st["A"], b=st["b"], G=st["G"] if p else None,
            h=st["h"] if p else None, lb=plan.lb, ub=plan.ub,
        )  # fmt: skip
        P_r = np.zeros((n + m, n + m))
        P_r[:n, :n] = P
        P_r[n:, n:] = np.diag(np.full(m, spec.task_weight))
        A_r = np.zeros((m, n + m))
        A_r[:, n:] = -np.eye(m)
        inf = np.full(m, math.inf)
        self.relaxed = solvers.Problem.trusted(
            P=P_r, q=np.zeros(n + m), A=A_r, b=st["b"], G=np.zeros((p, n + m)) if p else None,
            h=st["h"] if p else None, lb=np.concatenate([plan.lb, -inf]),
            ub=np.concatenate([plan.ub, inf]),
        )  # fmt: skip
        self.strict_backend, self.relaxed_backend = factory(), factory()
        self.brake = np.zeros(n)
        self.kernels = [
            Kernel(scale, (plan.objective_gradient, -gain, self.cost)),
            Kernel(open_box, (plan.lb, plan.ub)),
            *(plan.bind(k) for k in rows),
            Kernel(crossed, (plan.lb, plan.ub), True),
        ]
        """What assembles the QP once the tasks' rows are written: the cost, the bounds and
        the limits' rows; the status is the first joint whose bounds cross (else −1)."""

    def solve(self, status: int) -> Answer | None:
        """Solve this step's QP (assembled by :attr:`kernels`, whose ``status`` is −1):
        strict, else relaxed, else braking; None when even braking is impossible (crossed
        bounds)."""
        if status != -1:  # crossed bounds: the reference resolver fails the step
            return None
        plan = self.plan
        strict = self.problem
        solution = self.strict_backend.solve(strict)
        spent, status = solution.solver_time, "optimal"
        if not solution.found:
            r = self.relaxed
            G = strict.G if strict.G is not None else np.zeros((0, plan.n))
            G_r = r.G if r.G is not None else np.zeros((0, r.n))
            relaxed_data(strict.A, G, self.cost, plan.lb, plan.ub, r.A, G_r, r.q, r.lb, r.ub)
            solution = self.relaxed_backend.solve(r)
            spent, status = spent + solution.solver_time, "relaxed"
        if not solution.found or solution.x is None:
            if not braking(plan.lb, plan.ub, self.brake):
                return None
            x, status = self.brake, "braking"
        else:
            x = solution.x[: plan.n]
        return Answer(x, 0.0, solution.iterations, spent, status)

    def reset(self) -> None:
        """Forget the backends' warm starts."""
        self.strict_backend.reset()
        self.relaxed_backend.reset()
