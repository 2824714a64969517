"""Direct DAQP adapter: set up once, update, warm active set; DAQP's C API where it can.

Two ways to DAQP, the same calls in the same order:

- **DAQP's C functions from compiled code** (:mod:`solvers.daqp_c`), when the installed
  ``daqp`` is a version whose structures that module mirrors: the set-up allocates DAQP's
  workspace as ``daqp.Model.setup`` does, and each solve is one compiled call
  (:func:`~solvers.daqp_c.solve_stacked`): the copy into the buffers below, DAQP's update
  (``H`` passed, i.e. re-factored, only when ``P`` changed) and solve, and the check, with
  the time inside DAQP's calls read from the same clock as ``time.perf_counter``. The
  answers are bitwise those of the second way (tests/solvers/test_daqp_c.py).
- **``daqp.Model``** otherwise, as described below.

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

With ``daqp.Model``, the per-step cost (~8 µs on a dvqp-sized QP, of which ~4 µs in DAQP's
``update`` and ``solve``): the stacked data ``H``, ``f``, ``[G; A]``, ``bupper``, ``blower``
live in one buffer allocated at set-up. An update copies the problem's arrays into it in one
compiled call (:func:`solvers._fast.stack`; constant parts, e.g. ``-inf`` lower bounds of
the ``G`` rows, are written once), which also tells whether ``P`` changed; ``H`` is passed
only then, so DAQP re-factors it only then. ``bupper``/``blower`` are not passed: the model
keeps pointers to the very buffers given at set-up (``Model.setup`` does not copy float64
C-contiguous arrays), and passing ``f`` and ``A`` makes DAQP recompute ``v``, ``M`` and then
``d`` from both bounds. Should a DAQP version copy the bounds instead, the stale bounds
would make the warm answer fail the check, and the cold retry would still solve it right.

The check (:func:`solvers._kkt.stacked`) runs on that buffer, the bitwise copy of the
problem's data the solve used (DAQP only reads it), with the same compiled code as
:meth:`Solution.checked <solvers.Solution.checked>` on the problem's own arrays: three
arrays to pass instead of twelve. ``Model.solve`` returns fresh copies of ``x`` and
``lam``, which the solution keeps without copying them again (``y``, ``z``, ``z_box`` are
views of ``lam``). Both compiled calls are ordinary typed numba calls: ``stack`` gets the
problem's arrays, the argument tuple kept per problem object; a problem whose arrays the
compiled copy refuses (not float64 C-contiguous of the right dimensions: ``TypeError``) is
copied with NumPy from then on.

API notes (daqp 0.11): ``Model.update`` silently ignores arrays whose shape
differs from the set-up (no error), hence the structure key; every array must
be writable (typed memoryviews reject read-only buffers), which the buffers are.
"""

from __future__ import annotations

import contextlib
from collections.abc import Hashable
from time import perf_counter
from typing import Any, ClassVar

import daqp
import numpy as np

from . import daqp_abi, daqp_c
from ._fast import EMPTY_MATRIX, EMPTY_VECTOR, refresh, stack
from ._kkt import HAS_LB, HAS_UB, MISFITTING, stacked
from .problem import Problem
from .refusal import refusal
from .solution import Solution, judged
from .stateful import RawResult, StatefulBackend, solve_guarded

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
    daqp_c.CERTIFIED: "infeasible (certified)",  # no solve: see DaqpBackend.refutes
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
    restarts: ClassVar[bool] = True
    refutes: bool = True
    """Whether a cold restart after a refusal (in DAQP's C functions) first tries
    multipliers its workspace holds as a certificate that the problem admits no acceptable
    answer (:func:`solvers.farkas.refuted`, at :attr:`tolerance`): proved, it is refused
    without a solve (exit flag :data:`~solvers.daqp_c.CERTIFIED`, status ``"infeasible
    (certified)"``, 0 iterations). It tries the last answer's multipliers or those a caller
    held for the next restart (:func:`~solvers.daqp_c.hold_multipliers`: a relaxed problem's
    answer proves the strict one infeasible in most steps of a relaxed streak), then the
    infeasibility direction of the last refusal DAQP found (DAQP writes no multipliers then;
    its workspace holds the direction, which :func:`~solvers.daqp_c.stacked_solve` reads into
    a buffer of its own). So a warm refusal's restart is
    certified from the refusal's own direction in most cases. A refusal so proved is one the
    solve could not have escaped (no answer can pass the check): every answer, and which
    solves are refused, are the same with or without it (False: every restart solves); only
    the refusal's record differs: 0 iterations, and always infeasible, where DAQP's own solve
    might have stopped at its iteration or time limit first."""

    def __init__(self, *, tolerance: float | None = None, **settings: Any) -> None:
        super().__init__(tolerance=tolerance, **settings)
        self._model: Any = None
        self._n = self._p = self._m = self._ms = 0  # DAQP's n, rows of G, A, simple bounds
        self._data = np.zeros(0)  # H, f, M, upper, lower one after the other (see _setup)
        self._H = self._M = np.zeros((0, 0))
        self._f = self._upper = self._lower = np.zeros(0)
        self._layout: tuple[int, ...] = ()  # n, p, m, ms and HAS_LB | HAS_UB as given
        self._cuts: tuple[slice | None, ...] = ()  # y, z, z_box in DAQP's lam
        self._bound: Problem | None = None  # the problem whose arguments of stack are kept
        self._stack: tuple[Any, ...] | None = None  # None: copy _bound with NumPy
        self._sense = np.zeros(0, dtype=np.intc)  # the set-up's sense: equality rows flagged
        self._c: daqp_abi.Workspace | None = None  # DAQP called from compiled code (daqp_c)
        self._c_args: tuple[Any, ...] | None = None  # solve_stacked's, but the mode and answers
        self._attempt_call: daqp_c.AttemptCall | None = None  # compiled_attempt's

    @classmethod
    def known_settings(cls) -> set[str]:
        """Keys of ``daqp.Model().settings`` (DAQP itself ignores unknown keys)."""
        return set(daqp.Model().settings)

    def _release(self) -> None:
        if self._c is not None:
            self._c.close()
        self._model = self._bound = self._stack = self._c = self._c_args = None
        self._attempt_call = None

    def _structure_of(self, problem: Problem) -> Hashable:
        """The base key, kept while the same problem object comes back (it holds the same
        arrays, whose shapes a trusted problem's caller keeps fixed)."""
        if problem is self._bound and self._structure is not None:
            return self._structure
        return super()._structure_of(problem)

    def _bind(self, problem: Problem) -> None:
        """Keep the arguments of :func:`~solvers._fast.stack` for ``problem``: its arrays
        (fixed objects, rewritten in place from one solve to the next), empty placeholders
        for its absent blocks, and the set-up's buffer and sizes."""
        A, G, lb, ub, empty = problem.A, problem.G, problem.lb, problem.ub, EMPTY_VECTOR
        self._bound, self._c_args, self._attempt_call = problem, None, None
        self._stack = (
            problem.P,
            problem.q,
            EMPTY_MATRIX if A is None else A,
            empty if A is None else problem.b,
            EMPTY_MATRIX if G is None else G,
            empty if G is None else problem.h,
            empty if lb is None else lb,
            empty if ub is None else ub,
            self._data,
            *self._layout[:4],
        )

    def _fit(self, problem: Problem) -> None:
        """Refuse arrays whose shapes misfit ``problem``'s sizes (NumPy would broadcast them
        into the buffers), as the compiled copy refuses them."""
        n, p, m, ms = self._n, self._p, self._m, self._ms
        wanted = {"P": (n, n), "q": (n,), "A": (m, n), "b": (m,), "G": (p, n), "h": (p,)}
        wanted.update(lb=(ms,), ub=(ms,))
        for name, shape in wanted.items():
            array = getattr(problem, name)
            if array is not None and array.shape != shape:
                raise ValueError("the problem's arrays do not fit the set-up's sizes")

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

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        n, p, m = problem.n, problem.n_in, problem.n_eq
        ms = n if problem.has_bounds else 0
        self._n, self._p, self._m, self._ms, rows = n, p, m, ms, ms + p + m
        flags = (0 if problem.lb is None else HAS_LB) | (0 if problem.ub is None else HAS_UB)
        self._layout = (n, p, m, ms, flags)  # the trailing arguments of _kkt.stacked
        self._cuts = slice(ms + p, None), slice(ms, ms + p), slice(0, ms) if ms else None
        # One buffer, so that an update passes a single array to the compiled copy.
        data = self._data = np.empty(n * (n + 1 + p + m) + 2 * rows)
        f, M, up, low = n * n, n * n + n, n * (n + 1 + p + m), n * (n + 1 + p + m) + rows
        self._f, self._upper, self._lower = data[f:M], data[up:low], data[low:]  # (np.split: 15 µs)
        self._H, self._M = data[:f].reshape(n, n), data[M:up].reshape(p + m, n)
        self._upper[:], self._lower[:] = np.inf, -np.inf
        self._bound = None
        if daqp_abi.available():  # copied with NumPy: the solves' compiled call copies, not stack
            self._fit(problem)
            self._fill(problem)
            self._H[:] = problem.P  # DAQP's, and the reference that tells P changed
        else:
            self._load(problem)
        sense = self._sense = np.zeros(rows, dtype=np.intc)
        sense[rows - m :] = _SENSE_EQUALITY
        work = None
        if daqp_abi.available():
            start = perf_counter()
            with contextlib.suppress(daqp_abi.LayoutError):  # then never again: daqp.Model
                work = daqp_abi.Workspace(
                    self._H, self._f, self._M, self._upper, self._lower, sense, self.settings, guess
                )
        if work is not None:
            if work.flag < 0:
                work.close()
                return RawResult(None, f"setup failed: {EXIT_FLAGS.get(work.flag, work.flag)}")
            self._c = work
            return self._in_c(problem, daqp_c.AS_SET_UP, start)
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

    def _load(self, problem: Problem) -> int:
        """Copy ``problem`` into the set-up's buffers; return whether ``P`` changed."""
        if problem is not self._bound:
            self._bind(problem)
        changed = -2  # -2: copy with NumPy, -1: a misfit the compiled copy found
        if self._stack is not None:
            try:
                changed = stack(*self._stack)
            except TypeError:  # arrays the compiled copy refuses: NumPy copies this problem
                self._stack = None
        if changed < 0:
            self._fill(problem)  # NumPy names a misfit it sees
            if changed == -1 or problem.P.shape != self._H.shape:
                raise ValueError("the problem's arrays do not fit the set-up's sizes")
            changed = refresh(np.ascontiguousarray(problem.P, dtype=np.float64), self._H)
        return changed

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        if self._c is not None:
            return self._in_c(problem, daqp_c.WARM, perf_counter())
        changed = self._load(problem)
        start = perf_counter()
        # f and A suffice: DAQP then recomputes v, M and d, reading both bounds through its
        # pointers to the set-up's buffers, which were rewritten in place.
        if changed:
            flag = self._model.update(H=self._H, f=self._f, A=self._M)
        else:
            flag = self._model.update(f=self._f, A=self._M)
        if flag < 0:
            return RawResult(None, f"update failed: {EXIT_FLAGS.get(flag, flag)}")
        return self._run(problem, start)

    def _restart(self, problem: Problem, guess: np.ndarray | None) -> RawResult | Solution:
        """A cold solve in the kept model: every datum passed again with the set-up's
        ``sense``, which makes DAQP re-form its whole LDP and start its working set afresh
        from the equality rows alone, as its set-up does, without its allocations (a refused
        strict solve on probe-into-clamp: ~18 µs, ~50 µs with a set-up). A primal guess needs a
        set-up (``primal_start``)."""
        if (self._model is None and self._c is None) or guess is not None:
            self._release()
            return self._setup(problem, guess)
        if self._stack is None:
            self._bound = None  # bound afresh: the compiled copy is tried again
        if self._c is not None:
            return self._in_c(problem, daqp_c.RESTART, perf_counter())
        self._load(problem)
        start = perf_counter()
        flag = self._model.update(H=self._H, f=self._f, A=self._M, sense=self._sense)
        if flag < 0:
            return RawResult(None, f"update failed: {EXIT_FLAGS.get(flag, flag)}")
        return self._run(problem, start)

    def _in_c(self, problem: Problem, mode: int, start: float) -> RawResult | Solution:
        """Update (``mode``: :mod:`solvers.daqp_c`'s bits), solve and check in one compiled
        call (:func:`~solvers.daqp_c.solve_stacked`) on the arrays kept for ``problem``."""
        if problem is not self._bound:
            self._bind(problem)
        n, p, m, ms, flags = self._layout
        work = self._c
        assert work is not None
        x, lam = work.x, work.lam  # kept from solve to solve, as daqp.Model's (see Workspace)
        if self._stack is not None:
            if self._c_args is None:
                self._c_args = (*self._stack[:9], work.handles, work.words, *self._layout)
            try:
                out = daqp_c.solve_stacked(*self._c_args, mode, self._refute(), x, lam, work.ray)
            except TypeError:  # arrays the compiled copy refuses: NumPy copies this problem
                self._stack = None
        if self._stack is None:
            if self._load(problem):  # NumPy copied it (a misfit raises)
                mode |= daqp_c.REFACTOR
            out = daqp_c.solve_stacked(
                self._H,
                self._f,
                self._M[p:],
                self._upper[ms + p :],
                self._M[:p],
                self._upper[ms : ms + p],
                self._lower[:ms],
                self._upper[:ms],
                self._data,
                work.handles,
                work.words,
                n,
                p,
                m,
                ms,
                flags,
                mode,
                self._refute(),
                x,
                lam,
                work.ray,
            )  # the set-up's own buffers: the compiled copy onto themselves changes nothing
        stage, flag, iterations, spent = out[:4]
        if stage != daqp_c.SOLVED:
            return self._stage_failure(problem, out)
        # copies, as Model.solve returns them: the solution keeps them uncopied
        x, lam = x.copy(), lam.copy()
        return self._judge(problem, out[4:], x, lam, int(flag), int(iterations), spent)

    def compiled_call(self, problem: Problem) -> daqp_c.AttemptCall | None:
        """What compiled code needs to make the first attempt of this backend's next solve of
        ``problem`` itself (for :meth:`solvers.rows.RowDropping.compiled_attempt`): the warm
        one, or after a refusal the cold restart in the kept set-up (its ``mode``), as
        :meth:`solve` would make it; None if that attempt would not be made on DAQP's C
        functions with the compiled copy, or the problem's arrays cannot be packed into one
        struct (a read-only one: a validated problem's). The same object while nothing
        changes; finish with :meth:`adopt_call`."""
        if self._c is None or problem is not self._bound or self._stack is None:
            return None
        if not self._warm and self._structure is None:  # a new set-up: solve
            return None
        call = self._attempt_call
        if call is None or (call.tolerance, call.refute) != (self.tolerance, self._refute()):
            given = self._stack[:8]
            if not all(a.flags.writeable or a.size == 0 for a in given):
                return None
            n, p, m, ms, flags = self._layout
            work = self._c
            self._attempt_call = daqp_c.AttemptCall(
                *(a if a.flags.writeable else np.zeros(a.shape) for a in given),  # placeholders
                self._data,
                work.handles,
                work.words,
                n,
                p,
                m,
                ms,
                flags,
                np.zeros(1, dtype=np.int64),
                self.tolerance,
                self._refute(),
                work.x,
                work.lam,
                work.ray,
            )
        self._attempt_call.mode[0] = daqp_c.WARM if self._warm else daqp_c.RESTART
        return self._attempt_call

    def adopt_call(self, problem: Problem, start: float, out: tuple[float, ...]) -> Solution:
        """Finish the solve of ``problem`` begun at ``start`` (``perf_counter``) whose first
        attempt compiled code made with :meth:`compiled_call`'s arrays (``out``: its
        values, :func:`~solvers.daqp_c.stacked_solve`'s), as :meth:`solve` would: the answer
        judged (copied: the buffers are the next attempt's) and, a warm one refused, solved
        again cold."""
        call = self._attempt_call
        assert call is not None
        stage, flag, iterations, spent = out[:4]
        if stage >= daqp_c.SOLVED:  # checked or not, judged as solve judges it
            x, lam = call.x.copy(), call.lam.copy()
            solution = self._judge(problem, out[4:], x, lam, int(flag), int(iterations), spent)
        else:  # a misfit or a failed update: as the attempt in solve would say it
            solution = solve_guarded(self, problem, self._stage_failure, problem, out)
        if call.mode[0] == daqp_c.RESTART:  # the cold attempt: its answer is the solve's
            return self._settled(solution, start)
        return self.after_warm(problem, solution, start)

    def settle_mode(self) -> None:
        """Take the warm state that compiled code left in :meth:`compiled_call`'s ``mode``
        after making this backend's attempts itself (a run's compiled loop also restarts it
        cold after a refused warm answer, as :meth:`after_warm` does, and leaves ``mode``
        :data:`~solvers.daqp_c.WARM` after an accepted answer, else
        :data:`~solvers.daqp_c.RESTART`): the next solve starts warm only from an accepted
        answer."""
        if self._attempt_call is not None:
            self._warm = bool(self._attempt_call.mode[0] == daqp_c.WARM)

    def _refute(self) -> float:
        """:func:`~solvers.daqp_c.stacked_solve`'s ``refute``: the tolerance at which a
        restart tries the last refusal's multipliers (:attr:`refutes`), else -1."""
        return self.tolerance if self.refutes else -1.0

    def refusal_of(self, flag: float) -> str:
        """The refusal (:func:`solvers.refusal.refusal`) a refused answer with DAQP's exit
        ``flag`` counts as: its solution's :attr:`~solvers.Solution.refusal`."""
        return refusal(EXIT_FLAGS.get(int(flag)) or str(int(flag)), True)

    def _stage_failure(self, problem: Problem, out: Any) -> RawResult:
        stage, flag = out[:2]
        if stage == daqp_c.MISFITTED:
            self._fill(problem)  # NumPy names the misfit it sees
            raise ValueError("the problem's arrays do not fit the set-up's sizes")
        return RawResult(None, f"update failed: {EXIT_FLAGS.get(int(flag), int(flag))}")

    def _run(self, problem: Problem, start: float) -> Solution:
        x, _, flag, info = self._model.solve()
        solver_time = perf_counter() - start
        lam = info["lam"]
        # The check runs on the copy of the problem's data that the solve used (DAQP only
        # reads these buffers): the very values it would give on the problem's own arrays.
        try:
            values = stacked(self._data, x, lam, *self._layout)
        except TypeError:  # not float64 vectors: judged (Solution.checked) sorts it out
            values = MISFITTING
        # Model.solve returns fresh copies of x and lam: the solution keeps them uncopied.
        return self._judge(problem, values, x, lam, flag, info["iterations"], solver_time)

    def _judge(
        self,
        problem: Problem,
        values: tuple[float, ...],
        x: np.ndarray,
        lam: np.ndarray,
        flag: int,
        iterations: int,
        solver_time: float,
    ) -> Solution:
        y, z, box = self._cuts
        solution = judged(
            problem,
            values,
            x,
            lam[y],
            lam[z],
            None if box is None else lam[box],
            self.name,
            self.tolerance,
            EXIT_FLAGS.get(flag) or str(flag),
            iterations,
            solver_time,
        )
        if flag == daqp_c.CERTIFIED:
            solution.message = (
                "the multipliers held by the solver prove that no answer passes the check "
                f"at tolerance {self.tolerance:g} (nothing solved)"
            )
        return solution
