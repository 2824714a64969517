"""Every installed backend (direct and ``qpsolvers:`` path) against known solutions."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import Problem, Solution, available_backends, make_backend
from tests.solvers.qp_cases import equality_case, kkt_case, random_problem

BACKENDS = available_backends()


def assert_multipliers_match(solution: Solution, expected: np.ndarray | None, name: str) -> None:
    value = getattr(solution, name)
    if expected is None or value is None:
        return
    np.testing.assert_allclose(value, expected, atol=1e-4, err_msg=f"{solution.backend}: {name}")


@pytest.mark.parametrize("name", BACKENDS)
@pytest.mark.parametrize("seed", [0, 1])
def test_equality_only_qp_matches_closed_form_kkt_solution(name: str, seed: int) -> None:
    case = equality_case(np.random.default_rng(seed))
    backend = make_backend(name)
    solution = backend.solve(case.problem)
    assert solution.found, solution.message
    np.testing.assert_allclose(solution.x, case.x, atol=backend.tolerance)
    assert_multipliers_match(solution, case.y, "y")


@pytest.mark.parametrize("name", BACKENDS)
@pytest.mark.parametrize("infinite", [False, True], ids=["finite", "infinite"])
def test_active_inequalities_and_bounds_match_constructed_optimum(
    name: str, infinite: bool
) -> None:
    case = kkt_case(np.random.default_rng(3), infinite=infinite)
    backend = make_backend(name)
    solution = backend.solve(case.problem)
    assert solution.found, solution.message
    np.testing.assert_allclose(solution.x, case.x, atol=backend.tolerance)
    # Unified sign convention: stationarity P x + q + A^T y + G^T z + z_box = 0.
    assert solution.residuals is not None
    if solution.residuals.stationarity is not None:
        assert solution.residuals.stationarity <= 1e-5
        assert_multipliers_match(solution, case.y, "y")
        assert_multipliers_match(solution, case.z, "z")
        assert_multipliers_match(solution, case.z_box, "z_box")


@pytest.mark.parametrize("name", BACKENDS)
def test_random_qp_matches_quadprog_reference(name: str) -> None:
    pytest.importorskip("quadprog")
    problem = random_problem(np.random.default_rng(11))
    reference = make_backend("qpsolvers:quadprog").solve(problem).require()
    backend = make_backend(name)
    np.testing.assert_allclose(backend.solve(problem).require(), reference, atol=backend.tolerance)


@pytest.mark.parametrize("name", BACKENDS)
def test_unconstrained_and_bounds_only_problems(name: str) -> None:
    P, q = np.diag([1.0, 2.0, 4.0]), np.array([-1.0, 4.0, -8.0])
    backend = make_backend(name)
    free = backend.solve(Problem(P, q)).require()
    np.testing.assert_allclose(free, [1.0, -2.0, 2.0], atol=backend.tolerance)
    boxed = Problem(P, q, lb=[-np.inf, -1.0, -1.0], ub=[0.5, np.inf, 1.0])
    solution = backend.solve(boxed)
    np.testing.assert_allclose(solution.require(), [0.5, -1.0, 1.0], atol=backend.tolerance)
    if solution.z_box is not None:  # lower bound of x1 active, upper of x0 and x2
        assert solution.z_box[0] > 0 and solution.z_box[1] < 0 and solution.z_box[2] > 0


@pytest.mark.parametrize("name", BACKENDS)
def test_initial_guess_is_accepted(name: str) -> None:
    case = kkt_case(np.random.default_rng(5))
    backend = make_backend(name)
    guess = case.x + 0.01
    np.testing.assert_allclose(
        backend.solve(case.problem, initvals=guess).require(), case.x, atol=backend.tolerance
    )


@pytest.mark.parametrize("name", BACKENDS)
def test_infeasible_problem_returns_failure_without_raising(name: str) -> None:
    problem = Problem(np.eye(2), np.zeros(2), A=[[1.0, 1.0]], b=[3.0], lb=[-1.0, -1.0], ub=[1, 1])
    solution = make_backend(name).solve(problem)
    assert not solution.found
    assert solution.message
    assert solution.solve_time >= 0.0


@pytest.mark.parametrize("name", BACKENDS)
def test_solver_exception_or_nonconvex_input_never_escapes(name: str) -> None:
    # P is not checked for convexity; solvers raise, fail, or return a KKT point.
    problem = Problem(np.diag([1.0, -1.0]), [0.1, 0.2], lb=[-1.0, -1.0], ub=[1.0, 1.0])
    solution = make_backend(name).solve(problem)
    assert solution.found or solution.message


def test_exception_text_is_kept_in_the_failure_message() -> None:
    pytest.importorskip("quadprog")
    problem = Problem(np.diag([1.0, -1.0]), [0.1, 0.2])
    solution = make_backend("qpsolvers:quadprog").solve(problem)
    assert not solution.found
    assert solution.status == "exception"
    assert solution.message.startswith("qpsolvers:quadprog raised ")
    assert "positive definite" in solution.message


def test_highs_writes_nothing_to_standard_output(capfd: pytest.CaptureFixture[str]) -> None:
    if "qpsolvers:highs" not in available_backends():
        pytest.skip("HiGHS not installed")
    problem = Problem(P=np.eye(2), q=np.array([-1.0, 0.0]), lb=np.zeros(2), ub=np.ones(2))
    solution = make_backend("qpsolvers:highs").solve(problem)
    assert solution.found
    assert capfd.readouterr().out == ""
