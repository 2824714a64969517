"""Backends on the fast path: one trusted problem whose arrays are rewritten in place."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from solvers import Problem, RawResult, available_backends, make_backend
from tests.solvers.qp_cases import kkt_case, spd

DIRECT = {"osqp": "osqp", "clarabel": "clarabel", "daqp": "daqp", "proxqp": "proxsuite"}
FIELDS = ("P", "q", "A", "b", "G", "h", "lb", "ub")
N, M, P_FINITE, P_INF = 13, 4, 20, 20


def count_calls(backend: Any, method: str) -> list[int]:
    """Wrap ``backend.<method>`` so its calls are counted in the returned list."""
    calls = [0]
    original = getattr(backend, method)

    def counted(*args: Any) -> RawResult:
        calls[0] += 1
        return original(*args)

    setattr(backend, method, counted)
    return calls


class Workspace:
    """dvqp-like arrays: 4 equalities, finite rows, +inf rows (half with zero G), bounds."""

    def __init__(self, seed: int) -> None:
        self.rng = rng = np.random.default_rng(seed)
        self.P, self.q = spd(rng, N, floor=0.1), 2.0 * rng.standard_normal(N)
        self.A, self.b = rng.standard_normal((M, N)), np.zeros(M)
        self.G = rng.standard_normal((P_FINITE + P_INF, N))
        self.G[P_FINITE + P_INF // 2 :] = 0.0
        self.h = np.full(P_FINITE + P_INF, np.inf)
        self.lb, self.ub = np.zeros(N), np.zeros(N)
        self.center, self.width = 0.3 * rng.standard_normal(N), 0.2 + 0.3 * rng.random(N)
        self.margin = 0.05 * rng.random(P_FINITE)
        self.margin[::4] = 0.0
        self.move(0.0)
        self.problem = Problem.trusted(*(getattr(self, name) for name in FIELDS))

    def move(self, size: float) -> None:
        """Change every array in place by a step of relative ``size`` (keeps it feasible)."""
        rng = self.rng
        self.center += size * rng.standard_normal(N)
        self.q += size * 5.0 * rng.standard_normal(N)
        self.A += size * rng.standard_normal(self.A.shape)
        self.G[:P_FINITE] += size * rng.standard_normal((P_FINITE, N))
        np.dot(self.A, self.center, out=self.b)
        self.h[:P_FINITE] = self.G[:P_FINITE] @ self.center + self.margin
        np.subtract(self.center, self.width, out=self.lb)
        np.add(self.center, self.width, out=self.ub)
        self.lb[-1], self.ub[-1] = -np.inf, np.inf

    def fresh(self) -> Problem:
        """A validated copy of the current data."""
        return Problem(*(getattr(self, name) for name in FIELDS))


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_in_place_updates_solved_warm_match_fresh_cold_solves(name: str, module: str) -> None:
    pytest.importorskip(module)
    ws = Workspace(seed=1)
    backend = make_backend(name)
    setups = count_calls(backend, "_setup")
    retries = 0
    for step in range(40):
        ws.move(0.5 if step % 10 == 9 else 0.01)  # small drift, every 10th step a jump
        ws.P[:] = ws.P + 0.01 * np.eye(N) if step % 7 == 6 else ws.P
        warm = backend.solve(ws.problem)
        cold = make_backend(name).solve(ws.fresh())
        assert warm.found, warm.message
        assert cold.found, cold.message
        np.testing.assert_allclose(warm.x, cold.x, atol=2 * backend.tolerance)
        retries += warm.retried
    assert setups[0] == 1 + retries  # every other solve was an in-place update


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_a_change_of_p_alone_is_noticed(name: str, module: str) -> None:
    pytest.importorskip(module)
    ws = Workspace(seed=2)
    backend = make_backend(name)
    updates = count_calls(backend, "_update")
    before = backend.solve(ws.problem).require()
    ws.P *= 3.0  # nothing else changes
    after = backend.solve(ws.problem)
    assert updates[0] == 1 and not after.retried  # warm, and right the first time
    expected = make_backend(name).solve(ws.fresh()).require()
    np.testing.assert_allclose(after.require(), expected, atol=backend.tolerance)
    assert np.abs(expected - before).max() > 1e-3  # the change of P did matter


def test_daqp_passes_h_only_when_p_changed(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("daqp")
    from solvers import daqp_abi

    # daqp.Model's path (its calls can be spied on); DAQP's C functions are called with the
    # same mask (tests/solvers/test_daqp_c.py: bitwise the same answers as P changes)
    monkeypatch.setattr(daqp_abi, "available", lambda: False)
    ws = Workspace(seed=3)
    backend = make_backend("daqp")
    backend.solve(ws.problem).require()
    passed: list[bool] = []

    class Spy:  # daqp.Model's methods are read-only: wrap the model instead
        def __init__(self, model: Any) -> None:
            self.model = model

        def update(self, **data: Any) -> int:
            passed.append(data.get("H") is not None)
            return self.model.update(**data)

        def solve(self) -> Any:
            return self.model.solve()

    backend._model = Spy(backend._model)
    for step in range(6):
        ws.move(0.01)
        if step in (2, 4):
            ws.P[0, 0] += 0.5
        backend.solve(ws.problem).require()
    assert passed == [False, False, True, False, True, False]


def inactive_rows_case(seed: int) -> tuple[Any, dict[str, np.ndarray | None]]:
    """``kkt_case`` plus rows that cannot be active: ``h = +inf`` (zero and non-zero ``G``)."""
    rng = np.random.default_rng(seed)
    case = kkt_case(rng, infinite=True)
    p = case.problem
    assert p.G is not None and p.h is not None and case.z is not None
    extra = np.zeros((4, p.n))
    extra[1] = rng.standard_normal(p.n)
    extra[3] = rng.standard_normal(p.n)
    G = np.vstack([p.G, extra])
    h = np.concatenate([p.h, [np.inf, np.inf, 1.0, np.inf]])  # one zero row with finite h
    data = {
        name: None if getattr(p, name) is None else np.array(getattr(p, name)) for name in FIELDS
    }
    data.update(G=G, h=h)
    case.z = np.concatenate([case.z, np.zeros(4)])
    return case, data


@pytest.mark.parametrize("name", available_backends())
@pytest.mark.parametrize("trusted", [False, True], ids=["validated", "trusted"])
def test_infinite_h_rows_and_zero_g_rows_are_accepted_by_every_backend(
    name: str, trusted: bool
) -> None:
    case, data = inactive_rows_case(seed=6)
    problem = Problem.trusted(**data) if trusted else Problem(**data)
    backend = make_backend(name)
    for _ in range(2):  # cold, then warm for the stateful ones
        solution = backend.solve(problem)
        assert solution.found, solution.message
        np.testing.assert_allclose(solution.x, case.x, atol=backend.tolerance)
        if solution.z is not None:
            np.testing.assert_allclose(solution.z[-4:], 0.0, atol=1e-6)
