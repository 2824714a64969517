"""Strict task priorities: a step's levels resolved one after the other, each on any backend.

The hard tasks' rows ``A Q̇ = b`` come in L levels (rows ``breaks[k] .. breaks[k+1]`` of level
k, priority order). The limits are level 0, always hard. The step is the lexicographic
optimum::

    level k:  minimise   ½ Q̇ᵀ(W + H)Q̇ + (c − g)ᵀQ̇ + ½ ρ Σ_i w_i s_i²
              subject to A_j Q̇ = b_j + r_j   (j < k: each level above at what it achieved)
                         A_k Q̇ − s = b_k      (s = 0 when level k can be met exactly)
                         G Q̇ ≤ h,  lb ≤ Q̇ ≤ ub

each level optimised in what the levels above leave free, its own slack ``s`` used only when
it cannot be met exactly, and its achieved residual ``r_k = A_k Q̇ − b_k`` fixed as an
equality for the levels below; the cost (the paper's weighted ``∇w`` and the soft tasks) is
what every level's QP minimises among its optima, so the last level's answer is the step.

Every level's problem is an ordinary QP of :mod:`solvers`, set up once over the step's
arrays (:func:`strict_problem`, :func:`relaxed_problem`: pure functions of those arrays) and
solved by a backend of its own (warm-started from that level's previous step), so it works
with every backend, and each answer is checked from the problem data
(:meth:`solvers.Solution.checked`) like every answer. As few QPs as possible: first the levels
as far down as they can be met together (``rows <= n``: all of them unless a level has more
rows than the joints left) as one strict QP — when it is accepted, every level in it is met
exactly and that is the step; else level by level from the first not met: strict, else
relaxed, and after a level that gave way, the levels below together again. Two shortcuts give
the very answer of the levels one by one in one QP: when the levels together are refused, the
last of them relaxed with those above held exactly (accepted: those above could be met, and it
gave way in what they leave free); and a level with more rows than the joints the levels above
leave (a posture below other tasks), which is never met exactly, relaxed with those above held
exactly. Refused, the levels are taken one by one.

Levels that cannot all be met together (more rows than joints: a posture below other tasks)
are first tried without the backends: the nested null-space step (:meth:`Levels.nested`, the
baseline's :func:`~dvqp.resolution.pinv.pinv_step`: each level met as well as those above let
it, in least squares where it cannot be met exactly, rows weighed by their weights, then the
cost) is the optimum of the problem without its inequalities; if it keeps every constraint
and bound it is the lexicographic optimum, taken as the step (``"optimal"``: a level met in
least squares did not give way). Else some limit binds and the cascade below solves it on the
backend. (The ρ-weighted slack of the relaxed problems would trade a least-squares level
against the cost by about ``1/ρ``; the nested step meets it exactly.)

A level whose relaxed QP has no accepted answer ends the cascade: the step is the answer of
the level above (which keeps every limit and every level above), the levels from there give
way. If the first level has none, the step brakes (:class:`~dvqp.resolution.qp.QPSolver`).

DAQP has a native hierarchical mode (``break_points``, soft constraints); it is not used: its
``lam`` holds each soft row's slack perturbation, not the levels' multipliers, so its levels'
answers cannot be checked from their KKT conditions as every answer here is, and its soft rows
trade a level that could be met against the cost (a residual of ``ρ_soft · λ``, not 0).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from time import perf_counter

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp.resolution.pinv import pinv_step
from dvqp.workspace import QPBuffers
from solvers.jit import njit

Array = NDArray[np.float64]

NESTED_SLACK = 0.0
"""rad/s (or a constraint's units per s): how far the nested step
(:meth:`Levels.nested`) may sit past a bound or a constraint's right side and still be taken
as keeping it (the exact verification of the integrated step judges it then)."""

#: Shows one backend call: ``(kind, problem, solution)``, kind ``"strict"`` or ``"relaxed"``.
Count = Callable[[str, solvers.Problem, solvers.Solution], None]
#: The time-scaled attempt (:meth:`~dvqp.resolution.qp.QPSolver._slow_down`): its solution and
#: the fraction of the nominal progress made.
Slow = Callable[[], tuple[solvers.Solution, float]]


def strict_problem(qp: QPBuffers, rows: int, b: Array) -> solvers.Problem:
    """The levels whose rows are ``A[:rows]`` met exactly, ``A[:rows] Q̇ = b[:rows]``, with the
    step's cost, constraints and bounds (views of ``qp``'s arrays and of ``b``: nothing to copy
    per step)."""
    p = qp.h.shape[0]
    G, h = (qp.G, qp.h) if p else (None, None)
    return solvers.Problem.trusted(qp.P, qp.cost, qp.A[:rows], b[:rows], G, h, qp.lb, qp.ub)


def relaxed_problem(
    qp: QPBuffers, first: int, rows: int, weights: Array, task_weight: float, b: Array
) -> solvers.Problem:
    """Over ``x = [Q̇; s]``: ``A[:first] Q̇ = b[:first]`` (the levels above, held), ``A[first:rows]
    Q̇ − s = b[first:rows]`` (this level, with its slack), the step's constraints and bounds, and
    the cost plus ``½ ρ Σ w_i s_i²`` (``ρ`` the ``task_weight``, ``w`` the rows' ``weights``
    (m,)). Its ``Q̇`` columns are filled by :func:`load_relaxed`; ``b`` is shared."""
    n, p, m = qp.cost.shape[0], qp.h.shape[0], rows - first
    P = np.zeros((n + m, n + m))
    P[n:, n:] = np.diag(task_weight * weights[first:rows])
    A = np.zeros((rows, n + m))
    A[first:, n:] = -np.eye(m)
    inf = np.full(m, np.inf)
    return solvers.Problem.trusted(
        P,
        np.zeros(n + m),
        A,
        b[:rows],
        np.zeros((p, n + m)) if p else None,
        qp.h if p else None,
        np.concatenate([qp.lb, -inf]),
        np.concatenate([qp.ub, inf]),
    )


def load_relaxed(
    qp: QPBuffers, problem: solvers.Problem, P: Array | None = None, cost: Array | None = None
) -> None:
    """Copy this step's cost, task rows, constraints and bounds into ``problem``'s ``Q̇``
    columns (a :func:`relaxed_problem`; :func:`load_columns`); ``P`` (n, n) and ``cost``
    (n,) in place of the step's (e.g. :func:`dvqp.resolution.ray.ray_constants`)."""
    G = problem.G if problem.G is not None else np.zeros((0, problem.P.shape[0]))
    load_columns(
        qp.P if P is None else P,
        qp.cost if cost is None else cost,
        qp.A,
        qp.G,
        qp.lb,
        qp.ub,
        problem.P,
        problem.q,
        problem.A,
        G,
        problem.lb,
        problem.ub,
    )


@njit(separate=True, python=True)  # a run's compiled loop calls it, and load_relaxed
def load_columns(P, cost, A, G, lb, ub, into_P, into_q, into_A, into_G, into_lb, into_ub):  # type: ignore[no-untyped-def]
    """The step's ``P`` (n, n), ``cost`` (n,), task rows ``A``, constraints ``G`` and bounds
    ``lb``, ``ub`` (n,) copied into the first n columns of a relaxed problem's (``into_A``
    takes the first rows of ``A``; ``into_G`` (0, n + m) without constraints)."""
    n = cost.shape[0]
    for i in range(n):
        for j in range(n):
            into_P[i, j] = P[i, j]
        into_q[i] = cost[i]
        into_lb[i] = lb[i]
        into_ub[i] = ub[i]
    for i in range(into_A.shape[0]):
        for j in range(n):
            into_A[i, j] = A[i, j]
    for i in range(into_G.shape[0]):
        for j in range(n):
            into_G[i, j] = G[i, j]


@dataclass
class Outcome:
    """What the levels gave: the step ``x`` (n,) (None: not even the first level had an
    answer), ``status`` (``"optimal"``, ``"slowed"`` or ``"relaxed"``), the backend's
    iterations and time (s) over every call, ``rate`` (time scaling), and the last refusal's
    message."""

    x: Array | None
    status: str
    iterations: int | None
    solver_time: float
    rate: float
    message: str = ""


class _Calls:
    """The backend calls of one step: what they cost and the last accepted answer."""

    def __init__(self, count: Count, n: int, refused: solvers.Solution | None) -> None:
        self.count, self.n = count, n
        self.x: Array | None = None
        self.message = ""
        self.spent = 0.0 if refused is None else refused.solver_time
        self.iterations = 0 if refused is None else refused.iterations or 0
        self.counted = refused is None or refused.iterations is not None

    def attempt(
        self,
        kind: str,
        problem: solvers.Problem,
        backend: solvers.Backend,
        made: tuple[float, ...] | None = None,
    ) -> bool:
        """Solve ``problem`` on ``backend``; whether its answer was accepted (then :attr:`x`).
        ``made``: the values of its first attempt, made in compiled code on the backend's
        ``compiled_attempt`` (the backend finishes that solve: ``adopt_attempt``)."""
        if made is None:
            solution = backend.solve(problem)
        else:
            solution = backend.adopt_attempt(problem, perf_counter(), made)  # type: ignore[attr-defined]
        self.count(kind, problem, solution)
        self.spent += solution.solver_time
        self.counted = self.counted and solution.iterations is not None
        self.iterations += solution.iterations or 0
        if self.accepted(solution):
            return True
        self.message = solution.message
        return False

    def accepted(self, solution: solvers.Solution) -> bool:
        """Whether ``solution`` was accepted; then its joint velocities are :attr:`x`."""
        if solution.found and solution.x is not None:
            self.x = np.array(solution.x[: self.n])
            return True
        return False

    @property
    def answer(self) -> Array:
        """The last accepted answer (only read after an accepted attempt)."""
        assert self.x is not None
        return self.x

    def outcome(self, status: str, rate: float) -> Outcome:
        """The step's outcome with ``status`` and the path's progress ``rate``."""
        iterations = self.iterations if self.counted else None
        return Outcome(self.x, status, iterations, self.spent, rate, self.message)


class Levels:
    """The levels of a step's QP ``qp`` (rows ``breaks[k] .. breaks[k+1]`` of level k), each
    problem on its own backend from ``factory``; ``weights`` (m,) the rows' weights within
    their level, ``task_weight`` ``ρ``."""

    def __init__(
        self,
        factory: Callable[[], solvers.Backend],
        qp: QPBuffers,
        breaks: NDArray[np.int64],
        weights: Array,
        task_weight: float,
    ) -> None:
        self.factory, self.qp, self.task_weight = factory, qp, task_weight
        self.breaks, self.weights = [int(r) for r in breaks], np.asarray(weights, dtype=float)
        self.count = len(self.breaks) - 1
        n = qp.cost.shape[0]
        meetable = [k for k in range(self.count) if self.breaks[k + 1] <= n]
        self.reach = meetable[-1] if meetable else -1
        """The last level down to which the levels may be met together (no more rows than
        joints); −1: not even the first."""
        self.fixed = np.zeros(self.breaks[-1])
        """The right sides the levels below see: each level above at what it achieved."""
        self._strict: dict[int, tuple[solvers.Problem, solvers.Backend]] = {}
        self._relaxed: dict[int, tuple[solvers.Problem, solvers.Backend]] = {}

    def nested(self) -> Array | None:
        """The step when no limit is active, if it keeps every limit: the nested null-space
        step of the levels (:func:`~dvqp.resolution.pinv.pinv_step` over the step's ``A``,
        ``b``, the rows' weights, the cost and ``P``; a level that cannot be met exactly met in
        least squares), checked from the problem data against every constraint and bound
        (within :data:`NESTED_SLACK`). It is then the lexicographic optimum itself: the optimum
        without the inequalities, and it satisfies them. None: it breaks one (or is not
        defined), so some limit binds and the levels are solved one by one."""
        qp = self.qp
        n = qp.cost.shape[0]
        out, info = np.empty(n), np.zeros(3)
        breaks = np.asarray(self.breaks, dtype=np.int64)
        status = pinv_step(
            qp.A, qp.b, breaks, self.weights, qp.cost, np.ones(n), qp.P, True, 0.0, info, out
        )
        if status != -1 or not np.isfinite(out).all():
            return None
        if np.any(out < qp.lb - NESTED_SLACK) or np.any(out > qp.ub + NESTED_SLACK):
            return None
        if qp.h.shape[0] and np.any(qp.G @ out > qp.h + NESTED_SLACK):
            return None
        return out

    def reset(self) -> None:
        """Forget every level backend's warm start."""
        for _, backend in (*self._strict.values(), *self._relaxed.values()):
            backend.reset()

    def strict(self, level: int) -> tuple[solvers.Problem, solvers.Backend]:
        """The problem (and its backend) of the levels down to ``level`` met exactly."""
        if level not in self._strict:
            problem = strict_problem(self.qp, self.breaks[level + 1], self.fixed)
            self._strict[level] = problem, self.factory()
        return self._strict[level]

    def relaxed(self, level: int) -> tuple[solvers.Problem, solvers.Backend]:
        """The problem (and its backend) of ``level`` with its slack, the levels above held."""
        if level not in self._relaxed:
            first, rows = self.breaks[level], self.breaks[level + 1]
            problem = relaxed_problem(
                self.qp, first, rows, self.weights, self.task_weight, self.fixed
            )
            self._relaxed[level] = problem, self.factory()
        return self._relaxed[level]

    @property
    def together(self) -> bool:
        """Whether every level may be met together (no more rows than joints): then the first
        attempt is the strict QP of all the task rows."""
        return self.reach == self.count - 1

    def solve(
        self,
        count: Count,
        slow: Slow | None = None,
        refused: solvers.Solution | None = None,
        relaxed_values: tuple[float, ...] | None = None,
    ) -> Outcome:
        """The step: each level met as well as the limits and the levels above let it (see the
        module docstring). ``count`` is shown every backend call; ``slow``, if given, is tried
        once the levels that may be met together are not (time-scaled path following: the
        step then slows along the path, or its task becomes stopping on it, ``qp.b``);
        ``refused``: the levels together (:attr:`together`) were already tried, strict, and
        had no accepted answer (that call, counted); ``relaxed_values``: then the last level's
        relaxed problem, those above held, was attempted in compiled code too (a run's loop:
        :meth:`~dvqp.resolution.qp.QPSolver.relaxed_attempt`), its values."""
        qp = self.qp
        self.fixed[:] = qp.b
        calls = _Calls(count, qp.cost.shape[0], refused)
        status, rate = "optimal", 1.0
        tried: set[int] = set()  # strict problems refused since the held values last changed
        settled = 0
        attempt = calls.attempt
        while settled < self.count:
            top = self.reach
            if top >= settled and top not in tried:
                tried.add(top)
                if top + 1 < self.count:  # the next level cannot be met: relaxed, those held
                    if attempt("relaxed", *self._loaded(top + 1)):
                        self._hold(top + 1, calls.answer)
                        status, settled = "relaxed", top + 2
                        tried.clear()
                        continue
                else:
                    if refused is None and attempt("strict", *self.strict(top)):
                        settled = top + 1
                        continue
                    refused = None
                    if slow is not None and settled == 0:
                        solution, rate = slow()  # once: σ = 0 is then no better
                        slow = None
                        calls.spent += solution.solver_time
                        if calls.accepted(solution):
                            status = "slowed"
                            break
                        self.fixed[:] = qp.b  # the task of stopping on the path
                    made, relaxed_values = relaxed_values, None
                    if top > settled and attempt("relaxed", *self._loaded(top), made):
                        self._hold(top, calls.answer)
                        status, settled = "relaxed", top + 1  # the last level gave way
                        continue
            if top > settled and settled not in tried:
                tried.add(settled)
                if attempt("strict", *self.strict(settled)):
                    settled += 1
                    continue
            if not attempt("relaxed", *self._loaded(settled)):
                break
            self._hold(settled, calls.answer)
            status, settled = "relaxed", settled + 1
            tried.clear()
        if settled < self.count and calls.x is not None:
            status = "relaxed"  # the levels from `settled` give way to those above
        return calls.outcome(status, rate)

    def _hold(self, level: int, x: Array) -> None:
        """Hold ``level`` from now on at what ``x`` achieves (its right side, for the levels
        below)."""
        first, rows = self.breaks[level], self.breaks[level + 1]
        self.fixed[first:rows] = self.qp.A[first:rows] @ x

    def _loaded(self, level: int) -> tuple[solvers.Problem, solvers.Backend]:
        problem, backend = self.relaxed(level)
        load_relaxed(self.qp, problem)
        return problem, backend
