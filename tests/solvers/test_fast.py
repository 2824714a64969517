"""The fast path of solvers: ``Problem.trusted`` and the compiled KKT residuals."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, ProblemShapeError, Residuals, Solution
from solvers.residuals import kkt_residuals as compiled_residuals
from tests.solvers.oracle import kkt_residuals as numpy_residuals
from tests.solvers.qp_cases import kkt_case

FIELDS = ("P", "q", "A", "b", "G", "h", "lb", "ub")
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def arrays_of(problem: Problem) -> dict[str, np.ndarray | None]:
    """Writable float64 copies of a problem's arrays, keyed by field name."""
    return {
        name: None if getattr(problem, name) is None else np.array(getattr(problem, name))
        for name in FIELDS
    }


def test_trusted_problem_equals_the_validated_one() -> None:
    case = kkt_case(np.random.default_rng(0), infinite=True)
    data = arrays_of(case.problem)
    trusted = Problem.trusted(**data)
    validated = Problem(**data)
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(trusted, name), getattr(validated, name))
    assert (trusted.n, trusted.n_eq, trusted.n_in, trusted.has_bounds) == (
        validated.n,
        validated.n_eq,
        validated.n_in,
        validated.has_bounds,
    )
    assert isinstance(trusted, Problem)


def test_trusted_problem_shares_the_arrays_and_stays_frozen() -> None:
    data = arrays_of(kkt_case(np.random.default_rng(1)).problem)
    trusted = Problem.trusted(**data)
    for name in FIELDS:
        assert getattr(trusted, name) is data[name]  # no copy: in-place edits are seen
    assert data["q"] is not None and data["q"].flags.writeable
    with pytest.raises(dataclasses.FrozenInstanceError):
        trusted.q = np.zeros(3)  # type: ignore[misc]


def test_trusted_problem_treats_zero_row_blocks_as_absent() -> None:
    trusted = Problem.trusted(
        np.eye(2), np.zeros(2), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2)), np.zeros(0)
    )
    assert (trusted.A, trusted.b, trusted.G, trusted.h) == (None, None, None, None)
    assert (trusted.n_eq, trusted.n_in, trusted.has_bounds) == (0, 0, False)


def test_regular_constructor_still_copies_validates_and_freezes() -> None:
    data = arrays_of(kkt_case(np.random.default_rng(2), infinite=True).problem)
    problem = Problem(**data)
    assert problem.G is not data["G"] and not problem.G.flags.writeable
    assert problem.h is not None and np.isinf(problem.h).any()  # +inf in h is allowed
    with pytest.raises(ProblemShapeError, match=r"^h: must not be NaN or -inf"):
        Problem(**{**data, "h": np.full_like(data["h"], -np.inf)})


def assert_same(fast: tuple[Residuals, float], ref: tuple[Residuals, float]) -> None:
    """Equal to 1e-12 relative to the data scale, and None for the same fields."""
    (got, got_scale), (want, want_scale) = fast, ref
    pairs = [(getattr(got, f.name), getattr(want, f.name)) for f in dataclasses.fields(want)]
    pairs.append((got_scale, want_scale))
    for a, b in pairs:
        assert (a is None) == (b is None), (got, want)
        if a is not None:
            assert abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b), want_scale), (got, want)


def random_data(rng: np.random.Generator, blocks: dict[str, bool]) -> dict[str, np.ndarray]:
    """A QP of random data with some blocks absent and some infinite entries."""
    n, m, p = int(rng.integers(1, 9)), int(rng.integers(1, 4)), int(rng.integers(1, 10))
    M = rng.standard_normal((n, n))
    data: dict[str, np.ndarray] = {"P": M @ M.T, "q": 3.0 * rng.standard_normal(n)}
    if blocks["A"]:
        data["A"], data["b"] = rng.standard_normal((m, n)), rng.standard_normal(m)
    if blocks["G"]:
        G, h = rng.standard_normal((p, n)), rng.standard_normal(p)
        G[rng.random(p) < 0.2] = 0.0  # zero rows
        h[rng.random(p) < 0.3] = np.inf
        data["G"], data["h"] = G, h
    lb, ub = -rng.random(n), rng.random(n)
    lb[rng.random(n) < 0.3] = -np.inf
    ub[rng.random(n) < 0.3] = np.inf
    if blocks["lb"]:
        data["lb"] = lb
    if blocks["ub"]:
        data["ub"] = ub
    return data


@settings(max_examples=200, deadline=None)
@given(
    seed=seeds,
    blocks=st.fixed_dictionaries({k: st.booleans() for k in ("A", "G", "lb", "ub")}),
    given_duals=st.fixed_dictionaries({k: st.booleans() for k in ("y", "z", "z_box")}),
    trusted=st.booleans(),
)
def test_compiled_residuals_equal_the_numpy_reference(
    seed: int, blocks: dict[str, bool], given_duals: dict[str, bool], trusted: bool
) -> None:
    rng = np.random.default_rng(seed)
    data = random_data(rng, blocks)
    problem = Problem.trusted(**data) if trusted else Problem(**data)
    x = rng.standard_normal(problem.n)
    sizes = {"y": problem.n_eq, "z": problem.n_in, "z_box": problem.n}
    duals = {k: rng.standard_normal(size) if given_duals[k] else None for k, size in sizes.items()}
    if duals["z_box"] is not None:
        duals["z_box"][rng.random(problem.n) < 0.3] = 0.0
    assert_same(compiled_residuals(problem, x, **duals), numpy_residuals(problem, x, **duals))


@settings(max_examples=50, deadline=None)
@given(seed=seeds, infinite=st.booleans())
def test_compiled_residuals_of_an_exact_optimum_match_and_vanish(seed: int, infinite: bool) -> None:
    case = kkt_case(np.random.default_rng(seed), infinite=infinite)
    args = (case.problem, case.x, case.y, case.z, case.z_box)
    fast = compiled_residuals(*args)
    assert_same(fast, numpy_residuals(*args))
    assert fast[0].stationarity is not None and fast[0].stationarity <= 1e-9


def test_compiled_residuals_reject_a_multiplier_of_wrong_shape() -> None:
    case = kkt_case(np.random.default_rng(1))
    with pytest.raises(ProblemShapeError, match=r"^z: expected shape \(6,\), got \(5,\)"):
        compiled_residuals(case.problem, case.x, case.y, case.z[:5], case.z_box)


def test_checked_gives_the_same_verdict_and_residuals_on_trusted_and_regular_problems() -> None:
    case = kkt_case(np.random.default_rng(4), infinite=True)
    trusted = Problem.trusted(**arrays_of(case.problem))
    duals = {"y": case.y, "z": case.z, "z_box": case.z_box}
    for x in (case.x, case.x + 1e-4):
        verdicts = [
            Solution.checked(problem, x, backend="t", tolerance=1e-6, status="ok", **duals)
            for problem in (case.problem, trusted)
        ]
        assert verdicts[0].found == verdicts[1].found == (x is case.x)
        assert verdicts[0].message == verdicts[1].message
        assert verdicts[0].residuals == verdicts[1].residuals


def test_checked_rejects_nan_multipliers_and_a_non_finite_x() -> None:
    case = kkt_case(np.random.default_rng(5))
    z = case.z.copy()
    z[0] = np.nan
    nan_dual = Solution.checked(
        case.problem,
        case.x,
        backend="t",
        tolerance=1e-6,
        status="ok",
        y=case.y,
        z=z,
        z_box=case.z_box,
    )
    assert not nan_dual.found and "stationarity residual nan" in nan_dual.message
    x = case.x.copy()
    x[0] = np.inf
    bad = Solution.checked(case.problem, x, backend="t", tolerance=1e-6, status="ok", y=case.y)
    assert not bad.found and bad.message == "t said 'ok' but x is not finite"
    assert bad.residuals is None
