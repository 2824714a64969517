"""A backend that hands another only the inequality rows that apply.

A fixed-structure problem (:meth:`Problem.trusted`) may carry many rows ``G_r x ≤ +inf`` that
do not apply this solve (e.g. a damper far from its obstacle): they can never be active, yet a
solver pays for each (DAQP about 25 ns a row and solve for a 13-variable problem).
:class:`RowDropping` keeps a compact copy holding the rows with finite ``h`` and hands that to
its inner backend, so the solver sees only them.

A row keeps its slot in the copy while it applies (a new one takes the lowest free slot), so
a warm-started solver's working set, which names rows by index, stays right from one solve to
the next. The copy's size is a capacity: it grows (doubling) when the rows that apply need
more and shrinks to half when they fit in a quarter of it; the free slots up to it are
``0 · x ≤ +inf`` rows. The inner backend sets up again (cold) only when the capacity changes.
The solution names the problem given and its ``z`` is spread back to that problem's rows (0
for a row that does not apply); its residuals, computed on the copy, are the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .jit import njit
from .problem import Problem
from .protocol import Backend
from .solution import Solution


@njit
def compact(G, h, slot_of, row_of, Gc, hc) -> int:  # type: ignore[no-untyped-def]
    """Copy the rows ``r`` of ``G``, ``h`` with finite ``h`` into their slots of ``Gc``,
    ``hc`` (``slot_of[r]``, ``row_of[slot]``; −1: none), a new one into the lowest free slot,
    and free the slots of the others (``0 · x ≤ +inf``); returns the highest used slot + 1."""
    free, used = 0, 0
    for r in range(h.shape[0]):
        s = slot_of[r]
        if h[r] < math.inf:
            if s < 0:
                while row_of[free] >= 0:
                    free += 1
                s, slot_of[r], row_of[free] = free, free, r
            for c in range(G.shape[1]):
                Gc[s, c] = G[r, c]
            hc[s] = h[r]
        elif s >= 0:
            slot_of[r], row_of[s], hc[s] = -1, -1, math.inf
            for c in range(G.shape[1]):
                Gc[s, c] = 0.0
            free = min(free, s)
    for s in range(row_of.shape[0]):
        if row_of[s] >= 0:
            used = s + 1
    return used


@njit
def spread(z, row_of, out) -> None:  # type: ignore[no-untyped-def]
    """``out[row_of[s]] = z[s]`` for every used slot s, 0 elsewhere."""
    out[:] = 0.0
    for s in range(z.shape[0]):
        if row_of[s] >= 0:
            out[row_of[s]] = z[s]


@njit
def resized(used: int, capacity: int, rows: int) -> int:
    """The compact copy's capacity for ``used`` slots: ``capacity`` while they fit and fill
    at least a quarter of it, else (or with no capacity yet, 0) ``min(rows, max(8, 2 used))``,
    ``rows`` the given problem's."""
    if capacity == 0 or used > capacity or 4 * used < capacity:  # 0: none yet
        return min(rows, max(8, 2 * used))
    return capacity


@dataclass(frozen=True)
class AttemptRows:
    """What compiled code needs to make a :class:`RowDropping`'s next solve itself: the given
    problem's ``G``, ``h``, the copy's slots (``slot_of``, ``row_of``), its full-size ``Gc``,
    ``hc``, its ``capacity`` and the inner backend's warm call on the copy at that capacity
    (``call``, e.g. :class:`solvers.daqp_c.AttemptCall`)."""

    G: np.ndarray
    h: np.ndarray
    slot_of: np.ndarray
    row_of: np.ndarray
    Gc: np.ndarray
    hc: np.ndarray
    capacity: int
    call: Any


@dataclass
class _Copy:
    """The compact copy of one problem: slots, full-size buffers and the problem at its
    capacity."""

    source: Problem
    slot_of: np.ndarray
    row_of: np.ndarray
    G: np.ndarray
    h: np.ndarray
    capacity: int = 0
    problem: Problem | None = None

    def sized(self, used: int) -> Problem:
        """The compact problem, its capacity changed if ``used`` slots do not fit or fit in a
        quarter of it (:func:`resized`)."""
        capacity = resized(used, self.capacity, self.h.shape[0])
        if self.problem is None or capacity != self.capacity:
            self.capacity = c = capacity
            s = self.source
            self.problem = Problem.trusted(s.P, s.q, s.A, s.b, self.G[:c], self.h[:c], s.lb, s.ub)
        return self.problem


class RowDropping:
    """``inner`` (a :class:`~solvers.Backend`) given only the inequality rows that apply (see
    the module docstring); a problem without inequality rows goes to it as it is."""

    def __init__(self, inner: Backend) -> None:
        self.inner = inner
        self.name, self.tolerance = inner.name, inner.tolerance
        self._copy: _Copy | None = None
        self._attempt: AttemptRows | None = None  # compiled_attempt's

    def reset(self) -> None:
        """Drop the inner backend's warm start and the copy's slots."""
        self.inner.reset()
        self._copy = self._attempt = None

    def solve(self, problem: Problem, initvals: np.ndarray | None = None) -> Solution:
        """Solve ``problem`` through its compact copy."""
        if problem.G is None or problem.h is None:
            return self.inner.solve(problem, initvals)
        copy = self._copy
        if copy is None or copy.source is not problem:
            p, n = problem.G.shape
            copy = self._copy = _Copy(
                problem,
                np.full(p, -1, np.int64),
                np.full(p, -1, np.int64),
                np.zeros((p, n)),
                np.full(p, math.inf),
            )
        used = compact(problem.G, problem.h, copy.slot_of, copy.row_of, copy.G, copy.h)
        return self._spread(problem, copy, self.inner.solve(copy.sized(used), initvals))

    def attempts_compiled(self) -> bool:
        """Whether the inner backend can make attempts in compiled code (it has a
        ``compiled_call``): only then may :meth:`compiled_attempt` say anything but None."""
        return getattr(self.inner, "compiled_call", None) is not None

    def proves_refusals(self) -> bool:
        """Whether the inner backend's restarts try held multipliers as a proof that a
        problem admits no answer (its ``refutes``, :mod:`solvers.farkas`)."""
        return bool(getattr(self.inner, "refutes", False))

    def compiled_attempt(self, problem: Problem) -> AttemptRows | None:
        """What compiled code needs to make the next solve of ``problem`` itself, its rows
        dropped and the inner backend's warm attempt on them (e.g.
        :func:`solvers.daqp_c.solve_dropped`), or None if the inner backend cannot be called so
        now (no ``compiled_call`` of its own, or it says None) or the problem's ``G``, ``h``
        cannot be packed into a struct (read-only, not C-contiguous). The same object while nothing
        changes; finish with :meth:`adopt_attempt`. Compiled code must take the path of
        :meth:`solve` instead when the capacity would change (:func:`resized`)."""
        copy, inner = self._copy, getattr(self.inner, "compiled_call", None)
        if inner is None or copy is None or copy.source is not problem or copy.problem is None:
            return None
        call = inner(copy.problem)
        if call is None:
            return None
        kept, G, h = self._attempt, problem.G, problem.h
        if kept is not None and kept.call is call and kept.G is G:
            return kept
        if not (G.flags.writeable and h.flags.writeable and G.flags.c_contiguous):  # type: ignore[union-attr]
            return None  # not packable into a struct: solve
        c = copy.capacity
        self._attempt = AttemptRows(G, h, copy.slot_of, copy.row_of, copy.G, copy.h, c, call)
        return self._attempt

    def adopt_attempt(self, problem: Problem, start: float, out: tuple[float, ...]) -> Solution:
        """Finish the solve of ``problem`` begun at ``start`` (``perf_counter``) that compiled
        code made with :meth:`compiled_attempt`'s arrays (the rows dropped, the inner backend's
        warm attempt): as :meth:`solve` would."""
        copy = self._copy
        assert copy is not None and copy.problem is not None
        finish = self.inner.adopt_call  # type: ignore[attr-defined]
        return self._spread(problem, copy, finish(copy.problem, start, out))

    def settle_mode(self) -> None:
        """The inner backend's ``settle_mode`` (the warm state compiled code left it in)."""
        self.inner.settle_mode()  # type: ignore[attr-defined]

    def refusal_of(self, flag: float) -> str:
        """The inner backend's ``refusal_of``: the refusal a refused answer with its exit
        ``flag`` counts as."""
        return self.inner.refusal_of(flag)  # type: ignore[attr-defined,no-any-return]

    def _spread(self, problem: Problem, copy: _Copy, solution: Solution) -> Solution:
        """The solution of the compact copy as ``problem``'s: ``z`` spread to its rows."""
        z = solution.z
        if z is not None:
            z = np.empty(problem.h.shape[0])
            spread(solution.z, copy.row_of[: copy.capacity], z)
        solution.problem, solution.z = problem, z
        return solution
