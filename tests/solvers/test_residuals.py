"""Tests of solvers.residuals: laws that hold for every input, and the sign convention."""

from __future__ import annotations

import math
from dataclasses import astuple

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, ProblemShapeError, Solution, residuals
from solvers.residuals import Residuals, failed_checks, filled, kkt_residuals
from tests.solvers.oracle import kkt_residuals as oracle
from tests.solvers.qp_cases import equality_case, kkt_case

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


def test_residuals_of_a_shifted_optimum_equal_the_oracle() -> None:
    case = kkt_case(np.random.default_rng(6), infinite=True)
    x = case.x + 1e-3
    got = residuals(case.problem, list(x), case.y, case.z, case.z_box)  # any array-like
    want = oracle(case.problem, x, case.y, case.z, case.z_box)[0]
    assert astuple(got) == pytest.approx(astuple(want), rel=1e-12, abs=1e-15)
    assert residuals(case.problem, x).stationarity is None


DATA = ("P", "q", "A", "b", "G", "h", "lb", "ub")
#: Where a NaN goes (field, index) and the residual it must make NaN.
NAN_CASES = [
    ("h", 0, "inequality"),
    ("G", (0, 0), "inequality"),
    ("b", 0, "equality"),
    ("A", (0, 0), "equality"),
    ("lb", 0, "bounds"),
    ("ub", 1, "bounds"),
    ("P", (0, 0), "stationarity"),
    ("q", 0, "stationarity"),
    ("x", 0, "equality"),
    ("y", 0, "stationarity"),
    ("z", 0, "complementarity"),
    ("z_box", 0, "stationarity"),
]


@pytest.mark.parametrize(("field", "index", "residual"), NAN_CASES)
def test_a_nan_makes_its_residual_nan_and_never_passes(
    field: str, index: int | tuple[int, int], residual: str
) -> None:
    case = kkt_case(np.random.default_rng(7))
    data = {name: np.array(getattr(case.problem, name)) for name in DATA}
    point = {name: np.array(getattr(case, name)) for name in ("x", "y", "z", "z_box")}
    (point if field in point else data)[field][index] = np.nan
    problem = Problem.trusted(**data)  # the regular constructor refuses NaN data
    res, scale = kkt_residuals(problem, **point)  # type: ignore[arg-type]
    assert math.isnan(getattr(res, residual)), res
    assert any(phrase.startswith(residual) for phrase in failed_checks(res, 1e-6, scale))
    checked = Solution.checked(problem, backend="t", tolerance=1e-6, status="ok", **point)
    assert not checked.found
    if field == "h":  # what a NumPy max(0.0, nan) gives, and the package must not
        assert oracle(problem, **point)[0].inequality == 0.0  # type: ignore[arg-type]


def test_filled_residuals_are_the_dataclass_s_own() -> None:
    for values in ((1e-9, 2.0, 3.0), (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)):
        made, quick = Residuals(*values), filled(*values)
        assert quick == made and hash(quick) == hash(made) and repr(quick) == repr(made)
        with pytest.raises(AttributeError):
            quick.equality = 0.0  # type: ignore[misc]
