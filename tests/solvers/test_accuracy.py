"""qpbenchmark's accuracy metrics: the kernel's duality gap and the shifted geometric means."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, make_backend
from solvers.accuracy import METRICS, SHIFT, AccuracyTally, metrics, shifted_geometric_mean

qpsolvers = pytest.importorskip("qpsolvers")


def _problem(seed: int) -> Problem:
    """A feasible QP with equalities, inequalities (some active) and bounds (some active)."""
    rng = np.random.default_rng(seed)
    n = 9
    M = rng.normal(size=(n, n))
    return Problem(
        M @ M.T + np.eye(n),
        3.0 * rng.normal(size=n),
        A=rng.normal(size=(2, n)),
        b=0.1 * rng.normal(size=2),
        G=rng.normal(size=(12, n)),
        h=0.3 * np.abs(rng.normal(size=12)),
        lb=-0.4 * np.ones(n),
        ub=0.4 * np.ones(n),
    )


@pytest.mark.parametrize("backend", ["daqp", "osqp", "clarabel", "quadprog", "proxqp"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_duality_gap_equals_qpsolvers_own_on_each_backends_answer(backend: str, seed: int) -> None:
    problem = _problem(seed)
    try:
        solver = make_backend(backend)
    except Exception:
        pytest.skip(f"{backend} not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        answer = solver.solve(problem)
    assert answer.found and answer.residuals is not None
    p = problem
    theirs = qpsolvers.Solution(qpsolvers.Problem(p.P, p.q, p.G, p.h, p.A, p.b, p.lb, p.ub))
    theirs.x, theirs.y, theirs.z, theirs.z_box = answer.x, answer.y, answer.z, answer.z_box
    theirs.found = True
    assert answer.residuals.duality_gap == pytest.approx(theirs.duality_gap(), rel=1e-9, abs=1e-13)
    assert answer.residuals.stationarity == pytest.approx(
        theirs.dual_residual(), rel=1e-9, abs=1e-13
    )
    assert metrics(answer) == pytest.approx(
        (theirs.primal_residual(), theirs.dual_residual(), theirs.duality_gap()),
        rel=1e-9,
        abs=1e-13,
    )


def test_an_infinite_row_is_left_out_of_the_gap_and_a_wrong_point_has_one() -> None:
    problem = _problem(3)
    answer = make_backend("daqp").solve(problem)
    h = problem.h.copy()
    h[::4] = np.inf  # rows never active: their multipliers are 0, their terms nothing
    inactive = Problem(
        problem.P,
        problem.q,
        A=problem.A,
        b=problem.b,
        G=problem.G,
        h=h,
        lb=problem.lb,
        ub=problem.ub,
    )
    again = make_backend("daqp").solve(inactive)
    assert again.found and math.isfinite(again.residuals.duality_gap)  # type: ignore[union-attr]
    moved = make_backend("daqp").solve(problem)
    assert moved.x is not None and answer.residuals is not None
    x = moved.x + 0.05  # not the optimum: its gap with the optimum's multipliers is positive
    from solvers import residuals

    assert residuals(problem, x, answer.y, answer.z, answer.z_box).duality_gap > 1e-4  # type: ignore[operator]


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.0, 1e3), min_size=1, max_size=40))
def test_shifted_geometric_mean_is_qpbenchmarks_formula(values: list[float]) -> None:
    naive = math.exp(sum(math.log(v + SHIFT) for v in values) / len(values)) - SHIFT
    assert shifted_geometric_mean(values) == pytest.approx(naive, rel=1e-9, abs=1e-12)


def test_shifted_geometric_mean_refuses_what_qpbenchmark_refuses() -> None:
    for bad in ([], [-1.0], [math.inf], [math.nan]):
        with pytest.raises(ValueError, match="shifted geometric mean"):
            shifted_geometric_mean(bad)
    with pytest.raises(ValueError, match="shift"):
        shifted_geometric_mean([1.0], shift=0.5)


def test_tallies_merge_exactly_and_an_unanswered_call_counts_at_its_tolerance() -> None:
    answers = [make_backend("daqp").solve(_problem(seed)) for seed in range(6)]
    infeasible = Problem(
        np.eye(2), np.zeros(2), G=np.array([[1.0, 0.0], [-1.0, 0.0]]), h=np.array([-1.0, -1.0])
    )
    refused = make_backend("daqp").solve(infeasible)
    assert not refused.found
    whole, first, second = AccuracyTally(), AccuracyTally(), AccuracyTally()
    for i, answer in enumerate([*answers, refused]):
        whole.add(answer)
        (first if i < 3 else second).add(answer)
    first.merge(second)
    assert (first.solves, first.unanswered) == (whole.solves, whole.unanswered) == (7, 1)
    means = whole.means()
    assert means is not None and first.means() == pytest.approx(means, rel=1e-12)
    values = [metrics(a) for a in answers]
    for k, name in enumerate(METRICS):
        column = [v[k] for v in values if v is not None] + [refused.tolerance]
        assert means[name] == pytest.approx(shifted_geometric_mean(column), rel=1e-9)
    again = AccuracyTally.from_dict(whole.to_dict())
    assert again.means() == pytest.approx(means, rel=1e-12)
    assert AccuracyTally().means() is None and AccuracyTally().to_dict()["solves"] == 0
