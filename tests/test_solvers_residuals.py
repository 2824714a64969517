"""Tests of solvers.residuals: laws that hold for every input, and the sign convention."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, ProblemShapeError, residuals
from tests.solvers_qp_cases import equality_case, kkt_case

seeds = st.integers(min_value=0, max_value=2**32 - 1)


@settings(max_examples=50, deadline=None)
@given(seed=seeds, n=st.integers(2, 12), m=st.integers(1, 2))
def test_exact_kkt_solution_of_equality_qp_has_zero_residuals(seed: int, n: int, m: int) -> None:
    case = equality_case(np.random.default_rng(seed), n=n, m=m)
    res = residuals(case.problem, case.x, y=case.y)
    assert max(res.equality, res.inequality, res.bounds) <= 1e-9
    assert res.stationarity is not None and res.stationarity <= 1e-9


@settings(max_examples=50, deadline=None)
@given(seed=seeds, infinite=st.booleans())
def test_constructed_optimum_with_its_multipliers_has_zero_residuals(
    seed: int, infinite: bool
) -> None:
    case = kkt_case(np.random.default_rng(seed), infinite=infinite)
    res = residuals(case.problem, case.x, case.y, case.z, case.z_box)
    assert max(res.equality, res.inequality, res.bounds) <= 1e-9
    assert res.stationarity is not None and res.stationarity <= 1e-9
    assert res.complementarity is not None and res.complementarity <= 1e-9


@settings(max_examples=50, deadline=None)
@given(seed=seeds, n=st.integers(1, 10), p=st.integers(0, 8))
def test_random_feasible_point_has_zero_violations(seed: int, n: int, p: int) -> None:
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n)
    G = rng.standard_normal((p, n))
    A = rng.standard_normal((1, n))
    problem = Problem(
        np.eye(n),
        np.zeros(n),
        A=A,
        b=A @ x,
        G=G,
        h=G @ x + rng.uniform(0.0, 1.0, p),
        lb=x - rng.uniform(0.0, 1.0, n),
        ub=x + rng.uniform(0.0, 1.0, n),
    )
    res = residuals(problem, x)
    assert res.equality <= 1e-12
    assert (res.inequality, res.bounds) == (0.0, 0.0)
    assert res.stationarity is None and res.complementarity is None


def test_violations_are_measured_per_constraint_kind() -> None:
    problem = Problem(
        np.eye(2),
        np.zeros(2),
        A=[[1.0, 0.0]],
        b=[1.0],
        G=[[0.0, 1.0]],
        h=[0.5],
        lb=[-1.0, -np.inf],
        ub=[0.5, np.inf],
    )
    res = residuals(problem, np.array([1.25, 1.0]))
    assert res.equality == pytest.approx(0.25)
    assert res.inequality == pytest.approx(0.5)
    assert res.bounds == pytest.approx(0.75)


@pytest.mark.parametrize(
    ("constraint", "x", "multipliers"),
    [
        # min 1/2 x^2 - 2 x  s.t. x <= 1: active upper side, z = +1
        ({"G": [[1.0]], "h": [1.0]}, 1.0, {"z": [1.0]}),
        # the same through an upper bound: z_box = +1
        ({"ub": [1.0]}, 1.0, {"z_box": [1.0]}),
        # min 1/2 x^2 - 2 x  s.t. -x <= -3 (x >= 3): z = +1
        ({"G": [[-1.0]], "h": [-3.0]}, 3.0, {"z": [1.0]}),
        # x >= 3 as a lower bound: z_box = -1
        ({"lb": [3.0]}, 3.0, {"z_box": [-1.0]}),
    ],
)
def test_sign_convention_of_multipliers(
    constraint: dict[str, list], x: float, multipliers: dict[str, list[float]]
) -> None:
    problem = Problem([[1.0]], [-2.0], **constraint)
    res = residuals(problem, np.array([x]), **multipliers)
    assert res.stationarity == pytest.approx(0.0)
    assert res.complementarity == pytest.approx(0.0)
    flipped = {key: [-v for v in value] for key, value in multipliers.items()}
    assert residuals(problem, np.array([x]), **flipped).stationarity == pytest.approx(2.0)


def test_wrong_sign_or_slack_multiplier_shows_in_complementarity() -> None:
    problem = Problem(np.eye(1), [0.0], G=[[1.0]], h=[1.0], lb=[-1.0], ub=[np.inf])
    x = np.zeros(1)
    assert residuals(problem, x, z=[-0.5], z_box=[0.5]).complementarity == pytest.approx(0.5)
    assert residuals(problem, x, z=[0.5], z_box=[-0.5]).complementarity == pytest.approx(0.5)
    assert residuals(problem, x, z=[0.0], z_box=[0.25]).complementarity == pytest.approx(0.25)


def test_multiplier_of_wrong_shape_is_rejected() -> None:
    case = kkt_case(np.random.default_rng(1))
    with pytest.raises(ProblemShapeError, match=r"^z: expected shape \(6,\), got \(5,\)"):
        residuals(case.problem, case.x, case.y, case.z[:5], case.z_box)
