"""The per-step QP and its resolver: strict, else relaxed, else braking, on any backend.

Decision variable ``x = Q̇`` (rad/s), ``x = [Q̇; σ]`` when a path's progress is scaled, or
``x = [Q̇; s]`` when the hard tasks are relaxed by a slack ``s`` (task units per s)::

    minimise    ½ Q̇ᵀ (W + H) Q̇ + (c − g)ᵀ Q̇  (+ ½ ρ ‖s‖²)     g = λ ∂w/∂Q
    subject to  A Q̇ = b             (A Q̇ − s = b)            hard tasks (the tool's DV task)
                G Q̇ ≤ h                                      the limits' constraints
                lb ≤ Q̇ ≤ ub                                  the limits' bounds

``H, c`` are the soft tasks' costs (none in the paper). With no active inequality the KKT
conditions are exactly the weighted pseudoinverse step (:mod:`dvqp.resolution.pinv`). The
step writes the problem's arrays in place (:class:`~dvqp.workspace.QPBuffers`); every backend
gets the identical problem, set up once (``solvers.Problem.trusted`` over those arrays) and then
only updated. When the strict problem has no accepted answer (the tasks and the limits
conflict, or the answer does not pass the residual check), the relaxed one is solved: the step
keeps every limit and reports its task error (``"relaxed"``). In time-scaled path following
(a non-zero :attr:`QPSolver.feedforward` ``v``, the nominal motion along the path) a third
problem comes first: the task becomes ``A Q̇ = (b − v) + σ v`` with ``σ ∈ [0, 1]`` the fraction
of the nominal progress, rewarded by ``½ ρ ‖v‖² (1 − σ)²`` (what the relaxed problem's slack
``(1 − σ) v`` would cost): the tool slows along the path instead of leaving it
(``"slowed"``), and is relaxed, around ``σ = 0``, only when not even stopping on the path
holds it. If that fails too (the limits
conflict among themselves), the step brakes: the velocity closest to rest within the joint
bounds (``"braking"``), which the exact check of the integrated motion then accepts, splits or
fails.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from time import perf_counter
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

import solvers
from dvqp.errors import BackendError
from dvqp.resolution.levels import (
    Levels,
    load_columns,
    load_relaxed,
    relaxed_problem,
    strict_problem,
)
from dvqp.resolution.ray import ray_constants, ray_problem
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver
from dvqp.workspace import QPBuffers, as_struct
from solvers.accuracy import AccuracyTally, kernel_metrics
from solvers.daqp_c import ACCEPTED, WARM, solve_dropped
from solvers.jit import njit
from solvers.rows import RowDropping

#: A watcher of the backend calls: ``(kind, problem, solution)``, kind ``"strict"``,
#: ``"scaled"`` or ``"relaxed"``.
Watcher = Callable[[str, solvers.Problem, solvers.Solution], None]


def make_backend(name: str, **options: Any) -> solvers.Backend:
    """A fresh QP backend by name (see :func:`solvers.available_backends`), with ``options``
    (its settings).

    Raises
    ------
    BackendError
        Unknown or not installed (the message lists the installed backends), or a setting it
        does not take.
    """
    try:
        return solvers.make_backend(name, **options)
    except solvers.SolverError as exc:
        raise BackendError(str(exc)) from exc


class QPResolver(Resolver):
    """Resolves each step with a QP on a :mod:`solvers` backend.

    Parameters
    ----------
    spec
        Tasks, objective, limits and weights of the run.
    backend
        Backend name, e.g. ``"daqp"``, ``"osqp"``, ``"qpsolvers:quadprog"``, or a zero-argument
        callable returning a fresh :class:`solvers.Backend` (a run makes two: the strict and the
        relaxed problem keep their own warm starts).
    options
        Settings of the backend named by ``backend`` (e.g. ``{"eps_abs": 1e-6}``).
    """

    holds_limits = True

    def __init__(
        self,
        spec: StepSpec,
        backend: str | Callable[[], solvers.Backend],
        options: dict[str, Any] | None = None,
    ) -> None:
        super().__init__(spec)
        settings = dict(options or {})
        named = isinstance(backend, str)
        factory = (lambda: make_backend(backend, **settings)) if named else backend
        self.factory: Callable[[], solvers.Backend] = factory
        self.name = backend if isinstance(backend, str) else factory().name
        if isinstance(backend, str):
            factory()  # an unknown name fails here, not in the first step

    def solver(
        self,
        qp: QPBuffers,
        task_weight: float,
        levels: NDArray[np.int64],
        row_weights: NDArray[np.float64],
    ) -> QPSolver:
        """A :class:`QPSolver` on backends of :attr:`factory`, each handed only the rows of
        the QP that apply this step (:class:`solvers.rows.RowDropping`: a far obstacle's
        damper rows cost the solver nothing)."""
        factory = self.factory
        return QPSolver(lambda: RowDropping(factory()), qp, task_weight, levels, row_weights)


class Taken(NamedTuple):
    """A backend call's answer taken in compiled code (:meth:`QPSolver._call`): what the
    resolver reads of a :class:`solvers.Solution`. ``x`` is the backend's buffer, valid until
    its next call."""

    x: NDArray[np.float64]
    iterations: int
    solver_time: float
    found: bool = True
    message: str = ""


@dataclass
class Answer:
    """A QP solve: ``x`` (rad/s, None when even braking is impossible), the status
    (``"optimal"``, ``"slowed"``, ``"relaxed"``, ``"braking"``, or why it failed), the
    backend's iterations, the time inside its calls (s) and ``rate``, the fraction of the
    feed-forward's progress made (1 without time scaling)."""

    x: NDArray[np.float64] | None
    status: str
    iterations: int | None
    solver_time: float
    rate: float = 1.0


class QPSolver:
    """The step's QP over the plan's arrays, on two backends (strict and relaxed).

    Parameters
    ----------
    factory
        Makes a backend.
    qp
        The problem's arrays, rewritten in place every step.
    task_weight
        ``ρ`` of the relaxed problem's slack.
    breaks, weights
        The first row of each level of ``A`` and the number of rows ((L + 1,); None: one
        level), and each row's weight within its level ((m,); None: all 1).
    """

    def __init__(
        self,
        factory: Callable[[], solvers.Backend],
        qp: QPBuffers,
        task_weight: float,
        breaks: NDArray[np.int64] | None = None,
        weights: NDArray[np.float64] | None = None,
    ) -> None:
        self.qp = qp
        m = qp.b.shape[0]
        self.strict = strict_problem(qp, m, qp.b)
        weights = np.ones(m) if weights is None else np.asarray(weights, dtype=float)
        self.relaxed = relaxed_problem(qp, 0, m, weights, task_weight, qp.b)
        self.backends = factory(), factory()
        self.factory, self.task_weight = factory, task_weight
        self.levels = (
            Levels(factory, qp, breaks, weights, task_weight)
            if breaks is not None and len(breaks) > 2
            else None
        )
        """The levels of a step with hard tasks at several priorities (None: one level)."""
        self.ray = None if self.levels is not None else ray_problem(qp)
        """The strict task's least violation (:mod:`dvqp.resolution.ray`), whose multipliers a
        run's compiled loop holds to prove strict refusals (None with levels)."""
        self._prover: solvers.Backend | None = None  # the ray's, made by set_up_fallbacks
        self.feedforward = np.zeros(m)
        """The hard tasks' nominal motion this step, in their units per s, shape (m,): part
        of ``b``; when it is not zero, a step whose strict problem has no accepted answer slows
        along it before it relaxes (time-scaled path following). Zero: no time scaling."""
        self.scaled: solvers.Problem | None = None
        self._pacer: solvers.Backend | None = None
        self.refusals: Counter[str] = Counter()
        """Backend calls that gave no accepted answer, by :attr:`solvers.Solution.refusal`
        (the step then took the relaxed or braking path)."""
        self.accuracy = AccuracyTally()
        """qpbenchmark's accuracy metrics (:mod:`solvers.accuracy`) of each step's QP answer:
        the strict problem's, or the relaxed one's when the strict one had no accepted answer
        (an infeasible strict problem has no optimum to be accurate about: its refusal is
        counted in :attr:`refusals`); a step with neither counts at the check's tolerance."""
        self._packs: dict[int, tuple[Any, Any]] = {}  # per backend: compiled_attempt, packed
        self.watchers: list[Watcher] = []
        """Called after every backend call with ``("strict" | "scaled" | "relaxed", problem,
        solution)``;
        the problem's arrays are rewritten by the next step: a watcher copies what it keeps."""

    def fused_attempt(self) -> Any:
        """The strict backend's packed ``compiled_attempt`` of its next solve, for a caller
        that makes the attempt in a compiled call of its own (:func:`dvqp.step.stages.
        resolve_move`), then hands its values to :meth:`took` (taken) or :meth:`solve`
        (``attempted``); None when the step's first problem is not the strict one made that
        way (levels that cannot all be met together, watchers, a backend without compiled
        attempts)."""
        if (self.levels is not None and not self.levels.together) or self.watchers:
            return None
        return self._compiled_attempt(self.backends[0], self.strict)

    def relaxed_attempt(self) -> Any:
        """The relaxed backend's packed ``compiled_attempt`` of its next solve (as
        :meth:`fused_attempt`'s), for a caller that relaxes a step whose strict problem its
        cold attempt refused in compiled code (:func:`dvqp.motion.follow.follow`), then hands
        both attempts' values to :meth:`solve` (``attempted``, ``relaxed_values``) or counts the
        step (:meth:`count_refused`); None when it cannot (as :meth:`fused_attempt`). With
        levels that may all be met together, the last level's relaxed problem, the levels above
        held (:attr:`loop_relaxed`): the first QP of their cascade after that strict refusal
        (:meth:`~dvqp.resolution.levels.Levels.solve`), made only where the nested step breaks
        a limit (else the loop hands the step to :meth:`solve`, which takes it)."""
        if self.watchers:
            return None
        if self.levels is not None:
            if not self.levels.together:
                return None
            problem, backend = self.levels.relaxed(self.levels.count - 1)
            return self._compiled_attempt(backend, problem)
        return self._compiled_attempt(self.backends[1], self.relaxed)

    @property
    def loop_relaxed(self) -> solvers.Problem | None:
        """The problem :meth:`relaxed_attempt` solves (None: none): the relaxed problem, or
        with levels that may all be met together their last level's, relaxed with those
        above held at ``b`` (its ``b`` is :attr:`~dvqp.resolution.levels.Levels.fixed`)."""
        if self.levels is None:
            return self.relaxed
        if not self.levels.together:
            return None
        return self.levels.relaxed(self.levels.count - 1)[0]

    def load_relaxed_problem(self) -> None:
        """Load the relaxed problem from this step's QP (:func:`load_relaxed`, as a relaxed step
        does; each relaxed step loads it anew): its copy compiled (or loaded) before a run's
        first relaxed step, not in that step's time."""
        load_relaxed(self.qp, self.relaxed)

    def set_up_fallbacks(self) -> None:
        """Set the relaxed problem's backend up on the relaxed problem as it is loaded
        (:meth:`load_relaxed_problem`), and the least-violation problem's on that step's rows
        (:mod:`dvqp.resolution.ray`), before a run's steps: a run's first relaxed step is then
        a warm attempt that its compiled loop makes (:meth:`relaxed_attempt`), not a set-up in
        Python (0.7-1 ms), and the loop can prove strict refusals (:meth:`ray_attempt`).
        Neither counted nor watched: no step's calls. With levels, their last level's relaxed
        problem when they may all be met together (:attr:`loop_relaxed`), and no
        least-violation problem. Only for backends that make attempts in compiled code
        (``attempts_compiled``: DAQP's): another's set-up is the first relaxed step's, as before
        (a warm start changes its answers within its tolerance)."""
        compiled = getattr(self.backends[1], "attempts_compiled", None)
        if compiled is None or not compiled():
            return
        levels = self.levels
        if levels is not None and levels.together:
            problem, backend = levels.relaxed(levels.count - 1)
            levels.fixed[:] = self.qp.b
            load_relaxed(self.qp, problem)
            backend.solve(problem)
        if self.ray is None:
            return
        if self._prover is None:
            self._prover = self.factory()
        self.backends[1].solve(self.relaxed)
        eye, zero = ray_constants(self.qp.cost.shape[0])
        load_relaxed(self.qp, self.ray, eye, zero)
        self._prover.solve(self.ray)

    def ray_attempt(self) -> Any:
        """The least-violation problem's backend's packed ``compiled_attempt`` (as
        :meth:`relaxed_attempt`'s), for a run's compiled loop that proves strict refusals with
        its multipliers (:func:`dvqp.motion.follow.follow`); None when it cannot (as
        :meth:`fused_attempt`, or before :meth:`set_up_fallbacks`, or when the strict
        backend proves no refusal: ``proves_refusals``)."""
        proves = getattr(self.backends[0], "proves_refusals", None)
        if self.ray is None or self._prover is None or self.watchers or not proves:
            return None
        return self._compiled_attempt(self._prover, self.ray) if proves() else None

    def followed(self) -> None:
        """After a run's compiled loop made the strict backend's attempts (and its cold
        restarts, :func:`dvqp.motion.follow.follow`): the backend takes the warm state the
        loop left it in (``settle_mode``)."""
        self.backends[0].settle_mode()  # type: ignore[attr-defined]

    def count_refused(self, flags: NDArray[np.float64]) -> None:
        """Count the strict refusals of steps relaxed or slowed in compiled code (their
        answers' accuracy counted there): ``flags``, the refused cold attempts' exit flags,
        each named by the strict backend (``refusal_of``) as its refused solution would
        be."""
        strict = self.backends[0]
        for flag, count in zip(*np.unique(flags, return_counts=True), strict=True):
            self.refusals[strict.refusal_of(flag)] += int(count)  # type: ignore[attr-defined]

    def took(self, out: tuple[float, ...]) -> Taken:
        """The strict attempt made and taken in compiled code (its values ``out``), counted."""
        strict = self.backends[0]
        return self._took(strict, self._packs[id(strict)][0], out)

    def solve(
        self,
        rest: bool = False,
        attempted: tuple[float, ...] | None = None,
        relaxed_values: tuple[float, ...] | None = None,
        scaled_values: tuple[float, ...] | None = None,
    ) -> Answer:
        """Strict, else relaxed, else braking (``x`` a view, valid until the next solve).

        ``rest``: a step of a stop, whose cost has no linear part and whose tasks ask for no
        motion (``b = 0``). If ``Q̇ = 0`` is then feasible (every ``lb ≤ 0 ≤ ub``, ``h ≥ 0``)
        it is the exact minimiser of ``½ Q̇ᵀPQ̇`` (``P`` positive definite), taken without a
        backend: a backend's answer would be 0 only to its tolerance.

        ``attempted``: the values of the strict problem's first attempt, made in compiled code
        with :meth:`fused_attempt`'s struct and not taken there; the solve goes on from them.
        ``relaxed_values``: with them, the values of the relaxed problem's first attempt, made in
        compiled code too (:meth:`relaxed_attempt`) after that strict attempt, a cold one,
        was refused and the relaxed problem loaded; ``scaled_values`` so, the time-scaled
        problem's (:meth:`pacing_attempt`).
        """
        qp = self.qp
        if rest and not (np.any(qp.lb > 0.0) or np.any(qp.ub < 0.0) or np.any(qp.h < 0.0)):
            return Answer(np.zeros_like(qp.cost), "optimal", 0, 0.0)
        strict, relaxed = self.backends
        levels, refused = self.levels, None
        if levels is not None and levels.together:  # all the task rows, strict: as one level
            solution = refused = self._call("strict", strict, self.strict, attempted)
            if solution.found and solution.x is not None:
                x = solution.x[: qp.cost.shape[0]]
                return Answer(x, "optimal", solution.iterations, solution.solver_time)
        if levels is not None:  # not all met together, or together refused
            started = perf_counter()
            x = levels.nested()
            if x is not None:  # no limit binds: the lexicographic optimum, met in closed form
                spent = perf_counter() - started + (0.0 if refused is None else refused.solver_time)
                return Answer(x, "optimal", 0, spent)
        if levels is not None:
            slow = self._slow_down if not rest and self.feedforward.any() else None
            out = levels.solve(self._count, slow, refused, relaxed_values)
            if out.x is not None:
                return Answer(out.x, out.status, out.iterations, out.solver_time, out.rate)
            return self._brake(out.message, out.iterations, out.solver_time, out.rate)
        solution = self._call("strict", strict, self.strict, attempted)
        spent, status, rate = solution.solver_time, "optimal", 1.0
        if not solution.found and not rest and self.feedforward.any():
            solution, rate = self._slow_down(scaled_values)
            spent, status = spent + solution.solver_time, "slowed"
        if not solution.found:
            load_relaxed(qp, self.relaxed)
            solution = self._call("relaxed", relaxed, self.relaxed, relaxed_values)
            spent, status = spent + solution.solver_time, "relaxed"
        if solution.found and solution.x is not None:
            x = solution.x[: qp.cost.shape[0]]
            return Answer(x, status, solution.iterations, spent, rate)
        return self._brake(solution.message, solution.iterations, spent, rate)

    def _call(
        self,
        kind: str,
        backend: solvers.Backend,
        problem: solvers.Problem,
        attempted: tuple[float, ...] | None = None,
    ) -> Any:
        """One backend call on ``problem`` (``kind`` ``"strict"``, ``"scaled"`` or
        ``"relaxed"``), counted: a :class:`solvers.Solution`, or :class:`Taken`.

        A backend that can make its next solve's warm attempt in compiled code says so
        (``compiled_attempt``: :class:`solvers.rows.RowDropping` over DAQP's C functions,
        :func:`solvers.daqp_c.solve_dropped`). Then that attempt is one compiled call, and an
        answer that passes the residual check there (:func:`solvers.residuals.accepts`, the
        check of every solve) is taken without a :class:`solvers.Solution`; any other is
        finished by the backend as its ``solve`` would (``adopt_attempt``: judged, and a
        refused warm answer retried cold). Watchers see every call's problem and solution:
        with them, ``solve``."""
        start = perf_counter()
        if attempted is not None:  # made by the caller (fused_attempt)
            rows, out = self._packs[id(backend)][0], attempted
        else:
            warm = None if self.watchers else getattr(backend, "compiled_attempt", None)
            rows = None if warm is None else warm(problem)
            out = (-1.0,) if rows is None else solve_dropped(self._packed(backend, rows))
        if out[0] < 0:  # not made there
            solution = backend.solve(problem)
        else:
            if out[0] == ACCEPTED and rows.call.mode[0] == WARM:  # a restart's: the backend's
                return self._took(backend, rows, out)
            solution = backend.adopt_attempt(problem, start, out)  # type: ignore[attr-defined]
        self._count(kind, problem, solution)
        return solution

    def _took(self, backend: solvers.Backend, rows: Any, out: tuple[float, ...]) -> Taken:
        """A warm attempt's answer, accepted in compiled code, counted and taken as it is."""
        self.accuracy.add_metrics(kernel_metrics(out[4:]), backend.tolerance)
        return Taken(rows.call.x, int(out[2]), out[3])

    def _packed(self, backend: solvers.Backend, rows: Any) -> Any:
        """``rows`` (a backend's ``compiled_attempt``) packed into one struct, kept while the
        backend hands the same object."""
        kept = self._packs.get(id(backend))
        if kept is None or kept[0] is not rows:
            kept = self._packs[id(backend)] = (rows, as_struct(rows))
        return kept[1]

    def _brake(self, message: str, iterations: int | None, spent: float, rate: float) -> Answer:
        """No accepted answer: the velocity closest to rest within the joint bounds
        (``"braking"``), or a failure if those cross."""
        qp = self.qp
        if np.any(qp.lb > qp.ub):
            return Answer(None, f"failed: {message}", iterations, spent, 0.0)
        return Answer(np.clip(0.0, qp.lb, qp.ub), "braking", iterations, spent, rate)

    def _slow_down(self, attempted: tuple[float, ...] | None = None) -> tuple[Any, float]:
        """Solve the time-scaled problem (:func:`load_scaled`; from its first attempt's
        values ``attempted`` if compiled code made it, :meth:`pacing_attempt`); leave in
        ``b`` the task the answer meets (or, if it has none, the task of stopping on the
        path, ``b − v``, for the relaxed problem). Returns the solution and ``σ`` (0 if it
        has no accepted answer)."""
        qp, v = self.qp, self.feedforward
        n = qp.cost.shape[0]
        if self.scaled is None:
            self.scaled = self._scaled_problem()
            self._pacer = self.factory()
        p = self.scaled
        G = p.G if p.G is not None else np.zeros((0, n + 1))
        rho = float(self.task_weight)
        load_scaled(
            qp.P,
            qp.cost,
            qp.A,
            qp.b,
            qp.G,
            qp.lb,
            qp.ub,
            v,
            rho,
            p.P,
            p.q,
            p.A,
            p.b,
            G,
            p.lb,
            p.ub,
        )
        solution = self._call("scaled", self._pacer, p, attempted)  # type: ignore[arg-type]
        if not (solution.found and solution.x is not None):
            qp.b[:] -= v
            return solution, 0.0
        rate = min(max(float(solution.x[n]), 0.0), 1.0)
        qp.b[:] -= (1.0 - rate) * v
        return solution, rate

    def pacing_attempt(self) -> Any:
        """The time-scaled problem's backend's packed ``compiled_attempt`` of its next solve
        (as :meth:`relaxed_attempt`'s), for a caller that slows a step whose strict problem
        was refused in compiled code; None before a step was first slowed, or when it cannot
        (as :meth:`fused_attempt`)."""
        if self.levels is not None or self.watchers or self._pacer is None or self.scaled is None:
            return None
        return self._compiled_attempt(self._pacer, self.scaled)

    def _compiled_attempt(self, backend: solvers.Backend, problem: solvers.Problem) -> Any:
        """``backend``'s ``compiled_attempt`` of its next solve of ``problem``, packed; None
        if it has none (or says None)."""
        attempt = getattr(backend, "compiled_attempt", None)
        rows = None if attempt is None else attempt(problem)
        return None if rows is None else self._packed(backend, rows)

    def _scaled_problem(self) -> solvers.Problem:
        """The time-scaled problem's arrays, ``x = [Q̇; σ]`` (filled by :meth:`_slow_down`)."""
        qp = self.qp
        n, m, p = qp.cost.shape[0], qp.b.shape[0], qp.h.shape[0]
        G = np.zeros((p, n + 1)) if p else None
        return solvers.Problem.trusted(
            np.zeros((n + 1, n + 1)),
            np.zeros(n + 1),
            np.zeros((m, n + 1)),
            np.zeros(m),
            G,
            qp.h if p else None,
            np.append(qp.lb, 0.0),
            np.append(qp.ub, 1.0),
        )

    def _count(self, kind: str, problem: solvers.Problem, solution: solvers.Solution) -> None:
        """Tally one backend call (refusal, accuracy) and show it to the watchers."""
        if not solution.found:
            self.refusals[solution.refusal] += 1
        if solution.found or kind == "relaxed":  # the step's answer, or its last attempt
            self.accuracy.add(solution)
        for watch in self.watchers:
            watch(kind, problem, solution)

    def reset(self) -> None:
        """Forget the backends' warm starts, the refusals and accuracy counted (a run starts)."""
        self.refusals.clear()
        self.accuracy = AccuracyTally()
        self._packs.clear()
        for backend in (*self.backends, self._pacer, self._prover):
            if backend is not None:
                backend.reset()
        if self.levels is not None:
            self.levels.reset()


@njit(separate=True)  # a run's compiled loop calls it; QPSolver._slow_down when a run slows
def load_scaled(  # type: ignore[no-untyped-def]
    P,
    cost,
    A,
    b,
    G,
    lb,
    ub,
    v,
    task_weight,
    into_P,
    into_q,
    into_A,
    into_b,
    into_G,
    into_lb,
    into_ub,
):
    """The time-scaled problem of a step over ``x = [Q̇; σ]`` (:meth:`QPSolver._slow_down`):
    the step's arrays in its ``Q̇`` columns (:func:`~dvqp.resolution.levels.load_columns`),
    the tool rows' nominal motion ``v`` (m,) as ``σ``'s column ``−v``, the right side
    ``b − v``, and ``σ``'s cost ``½ρ‖v‖²(1 − σ)²`` (``ρ`` the ``task_weight``): its weight
    ``ρ‖v‖²`` on the diagonal and ``−ρ‖v‖²`` in the linear part."""
    load_columns(P, cost, A, G, lb, ub, into_P, into_q, into_A, into_G, into_lb, into_ub)
    n = cost.shape[0]
    norm = 0.0
    for i in range(v.shape[0]):
        norm += v[i] * v[i]
    weight = task_weight * norm
    for i in range(into_A.shape[0]):
        into_A[i, n] = -v[i]
        into_b[i] = b[i] - v[i]
    into_P[n, n] = weight
    into_q[n] = -weight
