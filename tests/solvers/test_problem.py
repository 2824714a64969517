"""Tests of solvers.Problem: conversion, shape and value validation."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import Problem, ProblemShapeError, SolverError

N = 5


def data(**overrides: object) -> dict[str, object]:
    """Valid keyword arguments for a Problem with n=5, 2 equalities, 3 inequalities."""
    rng = np.random.default_rng(0)
    base: dict[str, object] = {
        "P": np.eye(N),
        "q": np.ones(N),
        "A": rng.standard_normal((2, N)),
        "b": np.zeros(2),
        "G": rng.standard_normal((3, N)),
        "h": np.ones(3),
        "lb": -np.ones(N),
        "ub": np.ones(N),
    }
    base.update(overrides)
    return base


def test_valid_problem_reports_its_dimensions() -> None:
    problem = Problem(**data())
    assert (problem.n, problem.n_eq, problem.n_in) == (5, 2, 3)
    assert problem.has_bounds


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("P", np.eye(4), "P: expected shape (5, 5), got (4, 4)"),
        ("q", np.ones((N, 1)), "q: expected shape (n,), got (5, 1)"),
        ("A", np.ones((2, 4)), "A: expected shape (m, 5), got (2, 4)"),
        ("b", np.ones(3), "b: expected shape (2,), got (3,)"),
        ("G", np.ones((4, 6)), "G: expected shape (p, 5), got (4, 6)"),
        ("h", np.ones(2), "h: expected shape (3,), got (2,)"),
        ("lb", np.ones(4), "lb: expected shape (5,), got (4,)"),
        ("ub", np.ones((N, 1)), "ub: expected shape (5,), got (5, 1)"),
    ],
)
def test_shape_error_names_field_expected_and_actual_shape(
    field: str, value: np.ndarray, expected: str
) -> None:
    with pytest.raises(ProblemShapeError) as info:
        Problem(**data(**{field: value}))
    assert str(info.value) == expected


def test_shape_error_is_a_solver_error_and_a_value_error() -> None:
    with pytest.raises(ProblemShapeError) as info:
        Problem(**data(G=np.ones((4, 12))))
    assert isinstance(info.value, SolverError) and isinstance(info.value, ValueError)
    assert str(info.value) == "G: expected shape (p, 5), got (4, 12)"


@pytest.mark.parametrize(("given", "missing"), [("A", "b"), ("b", "A"), ("G", "h"), ("h", "G")])
def test_matrix_and_vector_must_come_together(given: str, missing: str) -> None:
    with pytest.raises(ProblemShapeError, match=f"^{missing}: must be given together"):
        Problem(**data(**{missing: None}))


@pytest.mark.parametrize("field", ["P", "q", "A", "b", "G"])
def test_non_finite_data_is_rejected_with_its_index(field: str) -> None:
    value = np.array(data()[field], dtype=float)
    value.flat[1] = np.nan
    with pytest.raises(ProblemShapeError, match=f"^{field}: must be finite"):
        Problem(**data(**{field: value}))


def test_infinite_h_and_bounds_are_allowed() -> None:
    h = np.array([1.0, np.inf, 2.0])
    lb = np.array([-np.inf, 0.0, -1.0, -np.inf, -2.0])
    ub = np.array([np.inf, 1.0, np.inf, 0.0, 2.0])
    problem = Problem(**data(h=h, lb=lb, ub=ub))
    assert np.isinf(problem.h).sum() == 1


@pytest.mark.parametrize(
    ("field", "bad"),
    [
        ("h", np.nan),
        ("h", -np.inf),
        ("lb", np.nan),
        ("lb", np.inf),
        ("ub", np.nan),
        ("ub", -np.inf),
    ],
)
def test_nan_and_infeasible_infinities_are_rejected(field: str, bad: float) -> None:
    value = np.array(data()[field], dtype=float)
    value[1] = bad
    with pytest.raises(ProblemShapeError, match=rf"^{field}: .*index 1\)"):
        Problem(**data(**{field: value}))


def test_crossed_bounds_are_rejected() -> None:
    lb = -np.ones(N)
    lb[3] = 2.0
    with pytest.raises(ProblemShapeError, match=r"^lb: must be <= ub \(first at index 3\)"):
        Problem(**data(lb=lb))


def test_asymmetric_cost_is_rejected() -> None:
    P = np.eye(N)
    P[0, 1] = 1.0
    with pytest.raises(ProblemShapeError, match=r"^P: must be symmetric"):
        Problem(**data(P=P))


def test_zero_row_constraints_are_treated_as_absent() -> None:
    problem = Problem(**data(A=np.zeros((0, N)), b=np.zeros(0), G=np.zeros((0, N)), h=None))
    assert problem.A is None and problem.b is None
    assert problem.G is None and problem.h is None
    assert (problem.n_eq, problem.n_in) == (0, 0)


def test_arrays_are_float64_c_contiguous_read_only_copies() -> None:
    G = np.asfortranarray(np.arange(15, dtype=np.int64).reshape(3, N))
    problem = Problem(**data(G=G))
    assert problem.G is not None
    assert problem.G.dtype == np.float64 and problem.G.flags.c_contiguous
    assert not problem.G.flags.writeable
    G[0, 0] = 99
    assert problem.G[0, 0] == 0.0


def test_unconvertible_data_names_the_field() -> None:
    with pytest.raises(ProblemShapeError, match=r"^q: cannot convert"):
        Problem(**data(q=["a", "b", "c", "d", "e"]))
