"""RowDropping: the inner backend sees only the rows that apply, the answer is the full
problem's (x and the multipliers), warm starts survive rows coming and going."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solvers import Problem, make_backend
from solvers.rows import RowDropping, compact
from tests.solvers.test_warmstart import count_setups


def walk(seed: int, steps: int, rows: int = 120, n: int = 8) -> list[tuple[np.ndarray, ...]]:
    """Data of a QP drifting step by step whose inequality rows apply (finite h) only now and
    then, a few at a time, as a far obstacle's damper rows do."""
    rng = np.random.default_rng(seed)
    G0, inside = rng.normal(size=(rows, n)), np.full(n, 0.5 / n)  # A inside = b, in the box
    out = []
    for k in range(steps):
        q = rng.normal(size=n) + 3.0 * np.sin(0.1 * k + np.arange(n))
        G = G0 + 0.01 * k
        near = np.abs(np.sin(0.07 * k * (1 + np.arange(rows) % 7) + np.arange(rows))) < 0.15
        h = np.where(near, G @ inside + 0.05, math.inf)
        out.append((q, np.where(near[:, None], G, 0.0), h))
    return out


def trusted(n: int, rows: int) -> Problem:
    P = np.eye(n) * 2.0
    A, b = np.ones((1, n)), np.array([0.5])
    lb, ub = -np.ones(n), np.ones(n)
    return Problem.trusted(P, np.zeros(n), A, b, np.zeros((rows, n)), np.zeros(rows), lb, ub)


@pytest.mark.parametrize("name", ["daqp", "osqp"])
def test_the_answer_is_the_full_problems_along_a_walk_of_rows_coming_and_going(name: str) -> None:
    full, dropped = trusted(8, 120), trusted(8, 120)
    plain, dropping = make_backend(name), RowDropping(make_backend(name))
    setups = count_setups(dropping.inner)
    active = 0
    for q, G, h in walk(3, 200):
        for p in (full, dropped):
            p.q[:], p.G[:], p.h[:] = q, G, h
        want, got = plain.solve(full), dropping.solve(dropped)
        assert got.found and want.found and got.problem is dropped
        np.testing.assert_allclose(got.x, want.x, atol=10 * plain.tolerance)
        assert got.z is not None and got.z.shape == (120,)
        assert not got.z[~np.isfinite(h)].any()  # a row that does not apply has no multiplier
        np.testing.assert_allclose(got.z, want.z, atol=1e-5)
        active += int((got.z > 1e-9).sum())
        assert dropping._copy is not None and dropping._copy.capacity < 120
    assert active > 0  # some rows were active
    assert setups[0] < 20  # warm updates, set up again only when the capacity changed


def test_a_row_keeps_its_slot_while_it_applies_and_a_new_one_takes_the_lowest_free() -> None:
    G = np.arange(12.0).reshape(6, 2)
    slot_of, row_of = np.full(6, -1, np.int64), np.full(6, -1, np.int64)
    Gc, hc = np.zeros((6, 2)), np.full(6, math.inf)
    inf = math.inf
    assert compact(G, np.array([inf, 1.0, inf, 2.0, inf, inf]), slot_of, row_of, Gc, hc) == 2
    assert list(row_of[:2]) == [1, 3] and list(hc[:2]) == [1.0, 2.0]
    np.testing.assert_array_equal(Gc[:2], G[[1, 3]])
    used = compact(G, np.array([5.0, inf, inf, 3.0, inf, 4.0]), slot_of, row_of, Gc, hc)
    assert used == 3 and list(row_of[:3]) == [5, 3, 0]  # row 3 kept its slot 1; row 0 took
    assert list(hc[:3]) == [4.0, 3.0, 5.0] and hc[3:].tolist() == [inf] * 3  # the free 2, 5 0
    used = compact(G, np.full(6, inf), slot_of, row_of, Gc, hc)
    assert used == 0 and not Gc.any() and (slot_of == -1).all() and (row_of == -1).all()


def test_the_capacity_grows_and_shrinks_with_the_rows_that_apply() -> None:
    problem, dropping = trusted(4, 64), RowDropping(make_backend("daqp"))
    capacities = []
    for live in (2, 30, 60, 3, 3):
        problem.G[:] = 0.0
        problem.h[:] = math.inf
        problem.G[:live, 0], problem.h[:live] = 1.0, 10.0
        assert dropping.solve(problem).found
        assert dropping._copy is not None
        capacities.append(dropping._copy.capacity)
    assert capacities == [8, 60, 60, 8, 8]
