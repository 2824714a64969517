"""Tests of solvers.Solution: the package's own verdict on a solver's answer."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import Backend, Problem, Solution, SolverFailure
from tests.solvers.qp_cases import KktCase, equality_case, kkt_case

TOL = 1e-6


@pytest.fixture
def case() -> KktCase:
    return kkt_case(np.random.default_rng(7))


def check(case: KktCase, x: np.ndarray | None, **multipliers: np.ndarray | None) -> Solution:
    return Solution.checked(
        case.problem, x, backend="fake", tolerance=TOL, status="solved", **multipliers
    )


def test_exact_answer_is_found_with_empty_message(case: KktCase) -> None:
    solution = check(case, case.x, y=case.y, z=case.z, z_box=case.z_box)
    assert solution.found
    assert solution.message == ""
    res = solution.residuals
    assert res is not None and max(res.equality, res.inequality, res.bounds) <= 1e-12
    np.testing.assert_array_equal(solution.require(), case.x)


def test_perturbed_answer_is_rejected_naming_the_residual(case: KktCase) -> None:
    x = case.x + 1e-3 * np.random.default_rng(0).standard_normal(case.x.size)
    solution = check(case, x)
    assert not solution.found
    assert solution.message.startswith("fake said 'solved' but equality residual ")
    assert "> tol 1e-06" in solution.message
    assert solution.residuals is not None and solution.residuals.stationarity is None


def test_feasible_but_suboptimal_answer_is_rejected_by_stationarity(case: KktCase) -> None:
    # Move along the null space of the active constraints: still feasible, not optimal.
    p = case.problem
    assert p.A is not None and p.G is not None
    active = np.vstack([p.A, p.G[case.z > 0], np.eye(p.n)[:2]])
    direction = np.linalg.svd(active)[2][-1]
    solution = check(case, case.x + 1e-3 * direction, y=case.y, z=case.z, z_box=case.z_box)
    res = solution.residuals
    assert res is not None and max(res.equality, res.inequality, res.bounds) <= TOL
    assert not solution.found
    assert "stationarity residual" in solution.message


def test_multiplier_of_wrong_sign_is_rejected(case: KktCase) -> None:
    z = case.z.copy()
    z[-1] = -1e-3  # an inactive row with a negative multiplier
    solution = check(case, case.x, y=case.y, z=z, z_box=case.z_box)
    assert not solution.found
    assert "complementarity residual" in solution.message


@pytest.mark.parametrize(
    ("x", "expected"),
    [
        (None, "fake returned no solution (status 'solved')"),
        (np.full(8, np.nan), "fake said 'solved' but x is not finite"),
        (np.zeros(7), "fake said 'solved' but x has shape (7,), expected (8,)"),
    ],
)
def test_missing_or_malformed_answer_is_rejected(
    case: KktCase, x: np.ndarray | None, expected: str
) -> None:
    solution = check(case, x)
    assert not solution.found
    assert solution.message == expected


def test_require_raises_solver_failure_carrying_the_solution(case: KktCase) -> None:
    solution = check(case, case.x + 1e-3)
    with pytest.raises(SolverFailure) as info:
        solution.require()
    assert info.value.solution is solution
    assert str(info.value) == solution.message


class LyingBackend:
    """Reports 'solved' with the unconstrained minimiser, ignoring every constraint."""

    name = "liar"
    tolerance = TOL

    def solve(self, problem: Problem, initvals: np.ndarray | None = None) -> Solution:
        x = np.linalg.solve(problem.P, -problem.q)
        return Solution.checked(
            problem, x, backend=self.name, tolerance=self.tolerance, status="solved"
        )

    def reset(self) -> None:
        pass


def test_backend_claiming_success_with_wrong_answer_is_reported_as_failure(case: KktCase) -> None:
    backend = LyingBackend()
    assert isinstance(backend, Backend)
    solution = backend.solve(case.problem)
    assert solution.status == "solved"
    assert not solution.found
    assert solution.message.startswith("liar said 'solved' but ")
    with pytest.raises(SolverFailure):
        solution.require()


def test_failure_record_carries_message_and_no_answer(case: KktCase) -> None:
    solution = Solution.failure(
        case.problem, backend="fake", tolerance=TOL, status="exception", message="boom"
    )
    assert (solution.found, solution.x, solution.message) == (False, None, "boom")


def test_an_answer_without_multipliers_is_not_trusted() -> None:
    case = equality_case(np.random.default_rng(8))
    with_duals = Solution.checked(
        case.problem, case.x, backend="t", tolerance=1e-8, status="solved", y=case.y
    )
    assert with_duals.found
    without = Solution.checked(case.problem, case.x, backend="t", tolerance=1e-8, status="solved")
    assert not without.found and "no multipliers" in without.message


def test_a_refusals_message_is_the_same_however_it_travels(case: KktCase) -> None:
    """Formatted when read (solvers.solution._Unmet): the same text read at once, after a
    pickle round trip, through ``dataclasses.replace``, and set by hand."""
    import dataclasses
    import pickle

    x = case.x + 1e-3 * np.random.default_rng(1).standard_normal(case.x.size)
    fresh, kept = check(case, x), check(case, x)
    travelled = pickle.loads(pickle.dumps(kept))
    text = fresh.message
    assert text.startswith("fake said 'solved' but equality residual ")
    assert travelled.message == text
    assert dataclasses.replace(kept).message == text == kept.message
    kept.message = "mine"
    assert kept.message == "mine" and repr(kept).count("mine") == 1
