"""Warm-started direct adapters: data updates, re-setup, and the retry-cold policy."""

from __future__ import annotations

import itertools
from typing import Any, ClassVar

import numpy as np
import pytest

from solvers import Problem, RawResult, SolverError, StatefulBackend, make_backend
from tests.solvers.qp_cases import equality_case, random_problem, random_walk

DIRECT = {"osqp": "osqp", "clarabel": "clarabel", "daqp": "daqp", "proxqp": "proxsuite"}
WALK = random_walk(seed=2)


def count_setups(backend: Any) -> list[int]:
    """Wrap the backend's cold set-up so calls are counted in the returned list."""
    calls = [0]
    setup = backend._setup

    def counted(*args: Any) -> RawResult:
        calls[0] += 1
        return setup(*args)

    backend._setup = counted
    return calls


def generic_failure_is_known(name: str, status: str) -> bool:
    """Whether a failure of the generic path is the documented proxqp one.

    ``proxqp.dense.solve`` (proxsuite 0.8) takes no ``eps_primal_inf``, so the
    ``qpsolvers:proxqp`` path keeps the default 1e-4 and sometimes calls a feasible
    problem infeasible; the direct adapter lowers it. Other paths must not fail.
    """
    return name == "proxqp" and status == "PROXQP_PRIMAL_INFEASIBLE"


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_direct_adapter_matches_qpsolvers_path_along_a_random_walk(name: str, module: str) -> None:
    pytest.importorskip(module)
    direct, generic = make_backend(name), make_backend(f"qpsolvers:{name}")
    setups = count_setups(direct)
    compared, retries = 0, 0
    for problem in WALK:
        ours, theirs = direct.solve(problem), generic.solve(problem)
        assert ours.found, ours.message
        retries += ours.retried
        if not theirs.found:
            assert generic_failure_is_known(name, theirs.status), theirs.message
            continue
        tol = max(direct.tolerance, generic.tolerance)
        np.testing.assert_allclose(ours.x, theirs.x, atol=tol)
        compared += 1
    assert compared >= 0.9 * len(WALK)
    row_changes = sum(a.n_in != b.n_in for a, b in itertools.pairwise(WALK))
    assert row_changes >= 4
    assert setups[0] == 1 + row_changes + retries  # everything else was a warm update


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_large_data_jump_is_still_solved_correctly(name: str, module: str) -> None:
    pytest.importorskip(module)
    pytest.importorskip("quadprog")
    backend, reference = make_backend(name), make_backend("qpsolvers:quadprog")
    rng = np.random.default_rng(4)
    backend.solve(WALK[0]).require()
    for _ in range(5):
        problem = random_problem(rng, p=WALK[0].n_in)
        expected = reference.solve(problem).require()
        np.testing.assert_allclose(
            backend.solve(problem).require(), expected, atol=backend.tolerance
        )


def test_proxqp_retry_after_spurious_warm_failure_gives_correct_answer() -> None:
    pytest.importorskip("proxsuite")
    pytest.importorskip("quadprog")
    # proxsuite's default eps_primal_inf (1e-4) makes warm starts after a large
    # jump report PROXQP_PRIMAL_INFEASIBLE on feasible problems.
    backend = make_backend("proxqp", eps_primal_inf=1e-4)
    reference = make_backend("qpsolvers:quadprog")
    rng = np.random.default_rng(3)
    backend.solve(random_problem(rng)).require()
    retried = []
    for _ in range(20):
        problem = random_problem(rng)
        solution = backend.solve(problem)
        assert solution.found, solution.message
        np.testing.assert_allclose(solution.x, reference.solve(problem).require(), atol=1e-6)
        if solution.retried:
            retried.append(solution)
    assert retried, "no warm start failed: the retry path was not exercised"


def test_reset_makes_the_next_solve_cold() -> None:
    pytest.importorskip("daqp")
    backend = make_backend("daqp")
    setups = count_setups(backend)
    backend.solve(WALK[0])
    backend.solve(WALK[1])
    backend.reset()
    backend.solve(WALK[2])
    assert setups[0] == 2


def exact(problem: Problem, offset: float = 0.0) -> RawResult:
    """Closed-form solution (x shifted by ``offset``) and multipliers of an equality QP."""
    assert problem.A is not None and problem.b is not None
    n, m = problem.n, problem.n_eq
    kkt = np.block([[problem.P, problem.A.T], [problem.A, np.zeros((m, m))]])
    sol = np.linalg.solve(kkt, np.concatenate([-problem.q, problem.b]))
    return RawResult(sol[:n] + offset, "solved", y=sol[n:])


class Scripted(StatefulBackend):
    """Solves exactly when cold; the warm path returns what the test scripts."""

    name = "scripted"
    default_tolerance: ClassVar[float] = 1e-9
    default_settings: ClassVar[dict[str, Any]] = {}

    def __init__(self, warm: Any = None, cold_offset: float = 0.0) -> None:
        super().__init__()
        self.warm, self.cold_offset = warm, cold_offset
        self.setups = self.updates = 0

    def _setup(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        self.setups += 1
        if isinstance(self.warm, type) and self.setups > 1:
            raise self.warm("cold set-up failed too")
        return exact(problem, self.cold_offset)

    def _update(self, problem: Problem, guess: np.ndarray | None) -> RawResult:
        self.updates += 1
        if isinstance(self.warm, type):
            raise self.warm("warm update failed")
        return exact(problem, self.warm or 0.0)


PROBLEMS = [equality_case(np.random.default_rng(seed)).problem for seed in range(3)]


def test_wrong_warm_answer_is_redone_cold_and_flagged_retried() -> None:
    backend = Scripted(warm=1e-3)
    assert not backend.solve(PROBLEMS[0]).retried
    solution = backend.solve(PROBLEMS[1])
    assert solution.found and solution.retried
    assert (backend.setups, backend.updates) == (2, 1)


def test_correct_warm_answer_is_kept() -> None:
    backend = Scripted(warm=0.0)
    for problem in PROBLEMS:
        solution = backend.solve(problem)
        assert solution.found and not solution.retried
    assert (backend.setups, backend.updates) == (1, 2)


def test_failure_after_retry_is_reported_and_next_solve_starts_cold() -> None:
    backend = Scripted(warm=1e-3, cold_offset=1e-3)
    first = backend.solve(PROBLEMS[0])
    assert not first.found and not first.retried  # cold already: nothing to retry
    second = backend.solve(PROBLEMS[1])
    assert not second.found and not second.retried
    assert (backend.setups, backend.updates) == (2, 0)
    assert second.message.startswith("scripted said 'solved' but equality residual")


def test_structure_change_triggers_setup_without_update() -> None:
    backend = Scripted(warm=0.0)
    backend.solve(PROBLEMS[0])
    backend.solve(equality_case(np.random.default_rng(0), n=7, m=3).problem)
    assert (backend.setups, backend.updates) == (2, 0)


def test_solver_exception_becomes_failure_and_programming_error_raises() -> None:
    backend = Scripted(warm=RuntimeError)
    backend.solve(PROBLEMS[0])
    solution = backend.solve(PROBLEMS[1])  # warm raises, cold raises
    assert not solution.found and solution.retried
    assert solution.message == "scripted raised RuntimeError: cold set-up failed too"
    buggy = Scripted(warm=TypeError)
    buggy.solve(PROBLEMS[0])
    with pytest.raises(SolverError, match="adapter error: TypeError: warm update failed"):
        buggy.solve(PROBLEMS[1])
