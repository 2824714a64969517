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
        quarter of it."""
        if self.problem is None or used > self.capacity or 4 * used < self.capacity:
            self.capacity = min(self.h.shape[0], max(8, 2 * used))
            s = self.source
            c = self.capacity
            self.problem = Problem.trusted(s.P, s.q, s.A, s.b, self.G[:c], self.h[:c], s.lb, s.ub)
        return self.problem


class RowDropping:
    """``inner`` (a :class:`~solvers.Backend`) given only the inequality rows that apply (see
    the module docstring); a problem without inequality rows goes to it as it is."""

    def __init__(self, inner: Backend) -> None:
        self.inner = inner
        self.name, self.tolerance = inner.name, inner.tolerance
        self._copy: _Copy | None = None

    def reset(self) -> None:
        """Drop the inner backend's warm start and the copy's slots."""
        self.inner.reset()
        self._copy = None

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
        solution = self.inner.solve(copy.sized(used), initvals)
        z = solution.z
        if z is not None:
            z = np.empty(problem.h.shape[0])
            spread(solution.z, copy.row_of[: copy.capacity], z)
        solution.problem, solution.z = problem, z
        return solution
