"""The per-step path of the DAQP adapter and the fast checks it relies on.

``Solution.adopt`` and ``solvers.solution.judged`` (with the values of ``_kkt.stacked``, the
check on DAQP's stacked copy of the data) must give the very Solution that the general
``Solution.checked`` gives on the problem's own arrays, accepted or rejected.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, Solution, make_backend
from solvers._fast import EMPTY_MATRIX, EMPTY_VECTOR, stack
from solvers._kkt import HAS_LB, HAS_UB, stacked
from solvers.solution import judged
from tests.solvers.qp_cases import kkt_case, spd

TOL = 1e-6
FIELDS = ("P", "q", "A", "b", "G", "h", "lb", "ub")
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def same_number(a: float | None, b: float | None) -> bool:
    return a is b or (a is not None and b is not None and (a == b or (a != a and b != b)))


def assert_same_solution(got: Solution, want: Solution) -> None:
    """Equal fields; residuals bitwise equal (NaN matching NaN)."""
    for name in ("found", "message", "status", "backend", "tolerance", "iterations"):
        assert getattr(got, name) == getattr(want, name), name
    assert (got.residuals is None) == (want.residuals is None)
    if got.residuals is not None and want.residuals is not None:
        for name in ("equality", "inequality", "bounds", "stationarity", "complementarity"):
            assert same_number(getattr(got.residuals, name), getattr(want.residuals, name)), name
    for name in ("x", "y", "z", "z_box"):
        a, b = getattr(got, name), getattr(want, name)
        assert (a is None) == (b is None), name
        if a is not None:
            np.testing.assert_array_equal(a, b)


def stacked_check(
    problem: Problem, x: np.ndarray, y: np.ndarray, z: np.ndarray, z_box: np.ndarray
) -> tuple[Solution, dict[str, np.ndarray | None]]:
    """The DAQP adapter's check: stack the data as it does, then ``stacked`` and ``judged``.

    Also returns the multipliers as the adapter hands them over (views of DAQP's ``lam``).
    """
    n, p, m = problem.n, problem.n_in, problem.n_eq
    ms = n if problem.has_bounds else 0
    rows = ms + p + m
    data = np.empty(n * (n + 1 + p + m) + 2 * rows)
    upper = n * (n + 1 + p + m)
    data[upper : upper + rows], data[upper + rows :] = np.inf, -np.inf
    arrays = [getattr(problem, name) for name in FIELDS]
    empty = [EMPTY_MATRIX, EMPTY_VECTOR] * 3 + [EMPTY_VECTOR] * 2
    arrays = [e if a is None else a for a, e in zip(arrays, empty, strict=True)]
    assert stack(*arrays, data, n, p, m, ms) >= 0
    lam = np.concatenate([z_box if ms else [], z if p else [], y if m else []])
    flags = (0 if problem.lb is None else HAS_LB) | (0 if problem.ub is None else HAS_UB)
    values = stacked(data, np.array(x), lam, n, p, m, ms, flags)
    duals = {"y": lam[ms + p :], "z": lam[ms : ms + p], "z_box": lam[:ms] if ms else None}
    return judged(problem, values, np.array(x), *duals.values(), "t", TOL, "ok", 3, 0.0), duals


def general_check(problem: Problem, x: np.ndarray, **duals: Any) -> Solution:
    return Solution.checked(
        problem, x, backend="t", tolerance=TOL, status="ok", iterations=3, **duals
    )


def candidates(rng: np.random.Generator, x: np.ndarray) -> list[np.ndarray]:
    """The optimum, points near it (rejected), and a non-finite one."""
    nan = x.copy()
    nan[0] = np.nan
    return [x, x + 1e-9 * rng.standard_normal(x.size), x + 1e-4 * rng.standard_normal(x.size), nan]


@settings(max_examples=60, deadline=None)
@given(seed=seeds, infinite=st.booleans(), trusted=st.booleans(), spoil=st.sampled_from(range(4)))
def test_fast_checks_give_the_solution_of_the_general_one(
    seed: int, infinite: bool, trusted: bool, spoil: int
) -> None:
    rng = np.random.default_rng(seed)
    case = kkt_case(rng, infinite=infinite)
    arrays = [getattr(case.problem, name) for name in FIELDS]
    writable = [None if a is None else np.array(a) for a in arrays]
    problem = Problem.trusted(*writable) if trusted else case.problem
    assert case.y is not None and case.z is not None and case.z_box is not None
    y, z, z_box = case.y.copy(), case.z.copy(), case.z_box.copy()
    if spoil == 1:
        z[-1] = -1e-3  # wrong sign on an inactive row
    elif spoil == 2:
        z_box[0] = np.nan
    elif spoil == 3:
        y *= 1.0 + 1e-3
    for x in candidates(rng, case.x):
        fast, duals = stacked_check(problem, x, y, z, z_box)
        want = general_check(problem, x, **duals)
        if x is case.x and spoil == 0:
            assert want.found, want.message
        elif x is not case.x and not np.allclose(x, case.x, atol=1e-6, equal_nan=False):
            assert not want.found  # far off, or not finite
        assert_same_solution(fast, want)
        adopted = Solution.adopt(
            problem, x.copy(), backend="t", tolerance=TOL, status="ok", iterations=3, **duals
        )
        assert_same_solution(adopted, want)


@settings(max_examples=80, deadline=None)
@given(
    seed=seeds,
    blocks=st.fixed_dictionaries({k: st.booleans() for k in ("A", "G", "lb", "ub")}),
    given_duals=st.fixed_dictionaries({k: st.booleans() for k in ("y", "z", "z_box")}),
)
def test_fast_checks_agree_with_missing_blocks_and_multipliers(
    seed: int, blocks: dict[str, bool], given_duals: dict[str, bool]
) -> None:
    rng = np.random.default_rng(seed)
    n, m, p = int(rng.integers(1, 9)), int(rng.integers(1, 4)), int(rng.integers(1, 10))
    data: dict[str, Any] = {"P": spd(rng, n), "q": rng.standard_normal(n)}
    if blocks["A"]:
        data["A"], data["b"] = rng.standard_normal((m, n)), rng.standard_normal(m)
    if blocks["G"]:
        data["G"], data["h"] = rng.standard_normal((p, n)), rng.standard_normal(p)
        data["h"][rng.random(p) < 0.3] = np.inf
    bound = rng.random(n)
    if blocks["lb"]:
        data["lb"] = np.where(rng.random(n) < 0.3, -np.inf, -bound)
    if blocks["ub"]:
        data["ub"] = np.where(rng.random(n) < 0.3, np.inf, bound)
    problem = Problem.trusted(**data)
    x = rng.uniform(-1.0, 1.0, n)
    sizes = {"y": problem.n_eq, "z": problem.n_in, "z_box": n}
    duals = {k: rng.standard_normal(s) if given_duals[k] else None for k, s in sizes.items()}
    adopted = Solution.adopt(
        problem, x.copy(), backend="t", tolerance=TOL, status="ok", iterations=3, **duals
    )
    assert_same_solution(adopted, general_check(problem, x, **duals))
    full = {k: rng.standard_normal(s) for k, s in sizes.items()}  # DAQP gives them all
    fast, handed = stacked_check(problem, x, **full)
    assert_same_solution(fast, general_check(problem, x, **handed))


def test_adopt_takes_odd_arrays_through_the_general_path() -> None:
    case = kkt_case(np.random.default_rng(3))
    assert case.y is not None and case.z is not None and case.z_box is not None
    strided = np.repeat(case.z, 2)[::2]  # not contiguous
    for x, z in ((case.x, strided), (case.x.astype(np.float32), case.z), (list(case.x), case.z)):
        duals = {"y": case.y, "z": z, "z_box": case.z_box}
        want = general_check(case.problem, np.asarray(x, dtype=float), **duals)
        answer: Any = x
        got = Solution.adopt(
            case.problem, answer, backend="t", tolerance=TOL, status="ok", iterations=3, **duals
        )
        assert_same_solution(got, want)
    short = Solution.adopt(case.problem, case.x[:-1], backend="t", tolerance=TOL, status="ok")
    assert short.message == f"t said 'ok' but x has shape ({case.x.size - 1},), expected (8,)"


class Drift:
    """dvqp-like trusted workspace (equalities, finite and +inf rows, bounds), moved in place."""

    def __init__(self, seed: int, n: int = 13, m: int = 4, p: int = 30) -> None:
        rng = self.rng = np.random.default_rng(seed)
        self.P, self.q = spd(rng, n, floor=0.1), rng.standard_normal(n)
        self.A, self.G = rng.standard_normal((m, n)), rng.standard_normal((p, n))
        self.G[p - 5 :] = 0.0
        self.b, self.h = np.zeros(m), np.full(p, np.inf)
        self.lb, self.ub = np.zeros(n), np.zeros(n)
        self.center, self.finite = np.zeros(n), p // 2
        self.move(0.0)
        self.problem = Problem.trusted(*(getattr(self, name) for name in FIELDS))

    def move(self, size: float, *, only_bounds: bool = False) -> None:
        rng, k = self.rng, self.finite
        self.center += size * rng.standard_normal(self.center.size)
        if not only_bounds:
            self.q += 5.0 * size * rng.standard_normal(self.q.size)
            self.G[:k] += size * rng.standard_normal((k, self.q.size))
        np.dot(self.A, self.center, out=self.b)
        self.h[:k] = self.G[:k] @ self.center + 0.05
        np.subtract(self.center, 0.4, out=self.lb)
        np.add(self.center, 0.4, out=self.ub)

    def fresh(self) -> Problem:
        return Problem(*(getattr(self, name) for name in FIELDS))


def test_daqp_warm_solutions_are_those_of_the_general_check() -> None:
    pytest.importorskip("daqp")
    ws = Drift(seed=4)
    backend = make_backend("daqp")
    previous = None
    for step in range(30):
        ws.move(0.3 if step % 10 == 9 else 0.01)
        solution = backend.solve(ws.problem)
        assert solution.found and not solution.retried, solution.message
        assert solution.x is not None and solution.x is not previous  # each solve's own x
        want = general_check(
            ws.problem, solution.x, y=solution.y, z=solution.z, z_box=solution.z_box
        )
        assert solution.residuals == want.residuals and want.found
        np.testing.assert_allclose(
            solution.x, make_backend("daqp").solve(ws.fresh()).require(), atol=2 * TOL
        )
        previous = solution.x
    data = backend._data.copy()  # DAQP only reads the stacked buffer
    assert stack(*backend._stack) == 0
    np.testing.assert_array_equal(backend._data, data)


@pytest.mark.parametrize("part", ["bounds", "h", "b"])
def test_daqp_sees_a_change_of_bounds_alone_warm(part: str) -> None:
    pytest.importorskip("daqp")
    ws = Drift(seed=5)
    backend = make_backend("daqp")
    backend.solve(ws.problem).require()
    for _ in range(3):
        if part == "bounds":
            ws.lb += 0.05
            ws.ub += 0.05
        elif part == "h":
            ws.h[: ws.finite] -= 0.02
        else:
            ws.move(0.05, only_bounds=True)
        warm = backend.solve(ws.problem)
        assert warm.found and not warm.retried, warm.message  # right the first time
        cold = make_backend("daqp").solve(ws.fresh()).require()
        np.testing.assert_allclose(warm.require(), cold, atol=2 * TOL)


@pytest.mark.parametrize("field", ["G", "P"])
def test_daqp_copies_problems_that_do_not_fit_the_compiled_copy_with_numpy(field: str) -> None:
    pytest.importorskip("daqp")
    ws = Drift(seed=6)
    fortran = np.asfortranarray(getattr(ws, field))
    arrays = {name: fortran if name == field else getattr(ws, name) for name in FIELDS}
    problem = Problem.trusted(**arrays)
    backend = make_backend("daqp")
    for _ in range(3):
        ws.move(0.01)
        fortran[:] = getattr(ws, field)
        solution = backend.solve(problem)
        assert backend._stack is None and solution.found and not solution.retried
        np.testing.assert_allclose(
            solution.x, make_backend("daqp").solve(ws.fresh()).require(), atol=2 * TOL
        )
    validated = make_backend("daqp")
    for _ in range(2):  # read-only arrays of validated problems take the compiled copy
        ws.move(0.01)
        assert validated.solve(ws.fresh()).found and validated._stack is not None


def test_daqp_survives_a_trusted_array_reshaped_in_place_or_misfit() -> None:
    pytest.importorskip("daqp")
    ws = Drift(seed=7)
    backend = make_backend("daqp")
    backend.solve(ws.problem).require()
    ws.q.shape = (ws.q.size, 1)  # the compiled copy refuses it, NumPy names the misfit
    reshaped = backend.solve(ws.problem)
    assert not reshaped.found and "ValueError" in reshaped.message
    ws.q.shape = (ws.q.size,)
    assert backend.solve(ws.problem).found and backend._stack is not None
    short = Problem.trusted(ws.P, ws.q, ws.A, ws.b, ws.G, ws.h[:-1], ws.lb, ws.ub)
    failed = backend.solve(short)
    assert not failed.found and "ValueError" in failed.message


def test_stacked_refuses_a_misfit_with_nan_values() -> None:
    values = stacked(np.zeros(3), np.zeros(1), np.zeros(1), 1, 0, 0, 0, 0)
    assert values[0] == -1 and all(math.isnan(v) for v in values[1:])


def engine(backend: Any) -> Any:
    """The DAQP a backend holds: its C workspace (solvers.daqp_c), else its daqp.Model."""
    assert backend._c is not None or backend._model is not None
    return backend._c if backend._c is not None else backend._model


def test_daqp_restarts_cold_in_its_model_after_a_refused_answer() -> None:
    """An infeasible verdict reached warm is confirmed by a cold restart, and the solve after
    a refusal starts cold too, both in the kept model (no new set-up): the very iterations and
    answer of a fresh set-up. (Without proofs: with them, the restart is certified from the
    refusal's own direction, ``tests/solvers/test_farkas.py``.)"""
    pytest.importorskip("daqp")
    ws = Drift(seed=8)
    backend = make_backend("daqp")
    backend.refutes = False
    backend.solve(ws.problem).require()
    model = engine(backend)
    ws.G[0] = 0.0
    ws.G[0, 0], ws.h[0] = 1.0, ws.lb[0] - 0.5  # x0 below its own bound
    refused = backend.solve(ws.problem)
    assert not refused.found and refused.retried and engine(backend) is model
    fresh = make_backend("daqp").solve(ws.fresh())
    assert not fresh.found and refused.iterations == fresh.iterations
    ws.move(0.01)
    after = backend.solve(ws.problem)
    cold = make_backend("daqp").solve(ws.fresh())
    assert after.found and not after.retried and engine(backend) is model
    assert after.iterations == cold.iterations
    np.testing.assert_array_equal(after.require(), cold.require())


def test_daqp_sets_up_a_new_model_after_a_solve_that_raised() -> None:
    pytest.importorskip("daqp")
    ws = Drift(seed=9)
    backend = make_backend("daqp")
    backend.solve(ws.problem).require()
    model = engine(backend)
    ws.q.shape = (ws.q.size, 1)  # the copy raises: a failure of status "exception"
    raised = backend.solve(ws.problem)
    assert not raised.found and raised.status == "exception"
    ws.q.shape = (ws.q.size,)
    assert backend.solve(ws.problem).found and engine(backend) is not model
