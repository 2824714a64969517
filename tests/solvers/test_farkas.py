"""Refusals proved from the problem data (``solvers.farkas``) and DAQP's restarts that use them.

The law: multipliers never prove a problem infeasible when some ``x`` passes the residual
check (whatever the multipliers); and a ray of an infeasible problem proves it, unless the
problem is feasible within the check's tolerance.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import make_backend
from solvers._fast import stack
from solvers.farkas import refuted
from solvers.problem import Problem
from tests.oracles.farkas import gap
from tests.solvers.test_daqp_fast import Drift

TAU = 1e-6


def stacked(A, b, G, h, lb, ub):  # type: ignore[no-untyped-def]
    """The problem's constraints laid out as DAQP's stacked copy (P = I, q = 0)."""
    n, m, p = lb.shape[0], b.shape[0], h.shape[0]
    rows = n + p + m
    data = np.zeros(n * (n + 1 + p + m) + 2 * rows)
    data[n * (n + 1 + p + m) + rows + n :] = -np.inf  # lower of the G rows: none
    A = np.ascontiguousarray(A.reshape(m, n))
    G = np.ascontiguousarray(G.reshape(p, n))
    assert stack(np.eye(n), np.zeros(n), A, b, G, h, lb, ub, data, n, p, m, n) >= 0
    return data, n, p, m


def proves(lam_y, lam_z, A, b, G, h, lb, ub, tolerance=TAU):  # type: ignore[no-untyped-def]
    """Whether ``y``, ``z`` prove the constraints infeasible at ``tolerance``."""
    data, n, p, m = stacked(A, b, G, h, lb, ub)
    lam = np.concatenate([np.zeros(n), lam_z, lam_y])
    return bool(refuted(data, lam, n, p, m, n, True, True, tolerance))


@settings(max_examples=200, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 6),
    m=st.integers(0, 4),
    p=st.integers(0, 5),
    scale=st.sampled_from([1e-8, 1.0, 1e6]),
)
def test_no_multipliers_prove_infeasible_constraints_that_an_answer_meets(
    seed: int, n: int, m: int, p: int, scale: float
) -> None:
    """``x0`` meets every row within the tolerance (off by up to τ): whatever ``y``, ``z``
    (random, of either sign, of sizes from 1e-8 to 1e6), no proof."""
    rng = np.random.default_rng(seed)
    lb, ub = -rng.uniform(0, 2, n), rng.uniform(0, 2, n)
    x0 = rng.uniform(lb, ub)
    A, G = rng.standard_normal((m, n)), rng.standard_normal((p, n))
    b = A @ x0 + rng.uniform(-TAU, TAU, m) * 0.999
    h = G @ x0 - rng.uniform(-1.0, TAU, p) * 0.999
    h[rng.random(p) < 0.2] = np.inf
    for _ in range(20):
        y, z = scale * rng.standard_normal(m), scale * rng.standard_normal(p)
        assert not proves(y, z, A, b, G, h, lb, ub)
        assert not proves(y, np.abs(z), A, b, G, h, lb, ub)


@settings(max_examples=300, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n=st.integers(1, 6),
    m=st.integers(0, 4),
    p=st.integers(0, 5),
    apart=st.floats(-1.0, 1.0),
)
def test_the_proof_is_the_inequality_written_out(
    seed: int, n: int, m: int, p: int, apart: float
) -> None:
    """Constraints made for multipliers ``y``, ``z`` to stand ``apart`` (relative) from a proof
    (positive: a proof): the compiled check says what the NumPy oracle's inequality says,
    wherever the two sides are not within rounding of each other."""
    rng = np.random.default_rng(seed)
    A, G = rng.standard_normal((m, n)), rng.standard_normal((p, n))
    y, z = rng.standard_normal(m), np.abs(rng.standard_normal(p))
    z[rng.random(p) < 0.2] = 0.0
    lb, ub = -rng.uniform(0, 2, n), rng.uniform(0, 2, n)
    h = rng.standard_normal(p)
    b = rng.standard_normal(m)
    v = A.T @ y + G.T @ z
    least = np.where(v > 0, v * lb, v * ub).sum()
    if m and np.abs(y).max() > 1e-3:  # b moved along y: yᵀb = L − zᵀh − apart·scale
        scale = np.abs(v).sum() * 2 + np.abs(y).sum() + np.abs(z).sum() + 1.0
        b += (least - z @ h - apart * scale - y @ b) * y / (y @ y)
    problem = SimpleNamespace(A=A, b=b, G=G, h=h, lb=lb, ub=ub)
    ratio = gap(problem, y, z, TAU)
    if not abs(ratio) > 1e-9:  # within rounding of a proof (or NaN): either answer is right
        return
    assert proves(y, z, A, b, G, h, lb, ub) == (ratio > 0)


def test_a_ray_proves_a_row_the_box_cannot_meet() -> None:
    """``x0 + x1 = b`` in the box [0, 1]²: ``y = −1`` proves it beyond ``2 + 2τ``, not
    within (``x = 1 + τ`` meets it within τ), and ``y = +1`` proves nothing."""
    A, G, h = np.ones((1, 2)), np.zeros((0, 2)), np.zeros(0)
    lb, ub, none = np.zeros(2), np.ones(2), np.zeros(0)
    assert proves(np.array([-1.0]), none, A, np.array([3.0]), G, h, lb, ub)
    assert not proves(np.array([1.0]), none, A, np.array([3.0]), G, h, lb, ub)
    assert proves(np.array([-2.5]), none, A, np.array([2.0 + 3.5 * TAU]), G, h, lb, ub)
    assert not proves(np.array([-1.0]), none, A, np.array([2.0 + 2.5 * TAU]), G, h, lb, ub)
    assert not proves(np.array([-1.0]), none, A, np.array([3.0]), G, h, lb, ub, tolerance=0.4)


def test_a_one_sided_row_proves_only_with_a_positive_multiplier_and_a_finite_bound() -> None:
    """``x0 ≤ −1`` against ``x0 ≥ 0``: ``z = 1`` proves it; ``z = −1`` is of the wrong sign,
    and a row without a bound (``h = +inf``) takes no part, whatever its multiplier."""
    A, b, lb, ub = np.zeros((0, 2)), np.zeros(0), np.zeros(2), np.ones(2)
    G, none = np.array([[1.0, 0.0], [0.0, 1.0]]), np.zeros(0)
    h = np.array([-1.0, np.inf])
    assert proves(none, np.array([1.0, 0.0]), A, b, G, h, lb, ub)
    assert proves(none, np.array([1.0, 5.0]), A, b, G, h, lb, ub)
    assert not proves(none, np.array([-1.0, 0.0]), A, b, G, h, lb, ub)
    assert not proves(none, np.array([0.0, 1.0]), A, b, G, h, lb, ub)


def test_a_product_that_underflows_proves_nothing() -> None:
    """``1e-300 x = 1`` met by ``x = 1e300`` (inside a box of ±1e301): ``y = −1e-30`` makes
    ``y A`` underflow to 0, which would make ``v = 0`` and ``L = 0 > U = −1e-30`` a false
    proof; the check proves nothing where a product loses its precision."""
    A, b, G, h, none = np.array([[1e-300]]), np.ones(1), np.zeros((0, 1)), np.zeros(0), np.zeros(0)
    wide = np.array([1e301])
    assert not proves(np.array([-1e-30]), none, A, b, G, h, -wide, wide)
    assert proves(np.array([-1.0]), none, A, b, G, h, -np.ones(1), np.ones(1))  # x ≤ 1: none


def test_an_unbounded_variable_that_the_multipliers_weigh_proves_nothing() -> None:
    data, n, p, m = stacked(
        np.zeros((0, 1)), np.zeros(0), np.ones((1, 1)), np.array([-1.0]), np.zeros(1), np.ones(1)
    )
    lam = np.array([0.0, 1.0])
    assert refuted(data, lam, n, p, m, n, True, True, TAU)
    assert not refuted(data, lam, n, p, m, n, False, True, TAU)  # no lower bound: x0 → −inf
    assert not refuted(data, lam, n, p, m, 0, False, False, TAU)


def infeasible(ws: Drift, by: float) -> None:
    """``x0`` kept below its own lower bound by ``by`` (row 0 of G)."""
    ws.G[0] = 0.0
    ws.G[0, 0], ws.h[0] = 1.0, ws.lb[0] - by


def test_a_restart_whose_held_multipliers_prove_its_problem_infeasible_solves_nothing() -> None:
    """A ray held in ``lam`` (row 0 against ``x0``'s lower bound, written there by hand)
    proves the next such problem infeasible: nothing
    solved, 0 iterations, its own status and message, no answer. A feasible problem after it
    is solved as by a backend that never tries the held multipliers, bitwise."""
    pytest.importorskip("daqp")
    proving, solving = make_backend("daqp"), make_backend("daqp")
    solving.refutes = False
    sides = Drift(seed=8), Drift(seed=8)
    for backend, ws in zip((proving, solving), sides, strict=True):
        backend.solve(ws.problem).require()
        infeasible(ws, 0.5)
        assert backend.solve(ws.problem).refusal == "infeasible"
    if proving._c is None:
        pytest.skip("the installed daqp's layout is not mirrored: no compiled restart")
    lam, ms = proving._c.lam, proving._layout[3]
    lam[:] = 0.0
    lam[ms] = 2.0  # z of row 0: x0 <= lb0 - 0.5 against lb0 <= x0
    held = lam.copy()
    for ws in sides:
        ws.move(0.001)
        infeasible(ws, 0.5)
    proved, solved = proving.solve(sides[0].problem), solving.solve(sides[1].problem)
    assert not proved.found and not solved.found
    assert proved.status == "infeasible (certified)" and proved.iterations == 0
    assert proved.refusal == solved.refusal == "infeasible" and solved.iterations > 0
    assert "prove that no answer passes the check" in proved.message
    assert proved.y is None and proved.z is None
    np.testing.assert_array_equal(lam, held)  # kept: the next restart tries it again
    for ws in sides:
        ws.move(0.001)
        ws.h[0] = np.inf
    after, want = proving.solve(sides[0].problem), solving.solve(sides[1].problem)
    assert after.found and want.found and after.iterations == want.iterations
    np.testing.assert_array_equal(after.x, want.x)
    fresh = make_backend("daqp")
    fresh.refutes = False
    assert fresh.solve(sides[0].fresh()).iterations == after.iterations


def made_infeasible(ws: Drift, kind: str, by: float, seed: int) -> None:
    """Make ``ws``'s problem infeasible by ``by`` at least: a row of G that keeps a joint
    below its lower bound, two rows of G whose half-spaces stand apart, or a task row pushed
    beyond what the box can reach (``b`` moved by ``20 + by`` times the row's reach)."""
    rng = np.random.default_rng(seed)
    n = ws.lb.shape[0]
    if kind == "row past the box":
        j = int(rng.integers(n))
        ws.G[0], ws.h[0] = 0.0, ws.lb[j] - by
        ws.G[0, j] = 1.0
    elif kind == "rows apart":
        d = rng.standard_normal(n)
        ws.G[1], ws.G[2] = d, -d
        ws.h[1], ws.h[2] = d @ ws.center - by, -(d @ ws.center) - by
    else:
        reach = 0.4 * np.abs(ws.A[0]).sum()
        ws.b[0] += reach * (1.0 + by) + 1.0


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    kind=st.sampled_from(["row past the box", "rows apart", "task out of reach"]),
    by=st.floats(1e-3, 1.0),
)
def test_a_refusal_daqp_finds_is_proved_by_its_own_direction(
    seed: int, kind: str, by: float
) -> None:
    """DAQP finds a problem infeasible on a dual direction that meets no blocking constraint
    (a Farkas ray) and writes no multipliers; the compiled solve writes that direction out.
    A warm attempt DAQP refuses so is then certified at its cold restart, nothing solved, and
    the direction proves the problem infeasible by the NumPy oracle's inequality (not only by
    the compiled check). Without proofs (``refutes`` False) the restart solves (iterations >
    0) and refuses as well."""
    pytest.importorskip("daqp")
    proving, solving = make_backend("daqp"), make_backend("daqp")
    solving.refutes = False
    sides = Drift(seed=seed % 1000), Drift(seed=seed % 1000)
    for backend, ws in zip((proving, solving), sides, strict=True):
        backend.solve(ws.problem).require()  # warm from here
        ws.move(0.01)
        made_infeasible(ws, kind, by, seed)
    if proving._c is None:
        pytest.skip("the installed daqp's layout is not mirrored: no compiled restart")
    proved, solved = proving.solve(sides[0].problem), solving.solve(sides[1].problem)
    assert proved.status == "infeasible (certified)" and proved.iterations == 0
    assert solved.refusal == "infeasible" and solved.iterations > 0
    ray, ms, p = proving._c.ray, proving._layout[3], proving._layout[1]
    y, z = ray[ms + p :], ray[ms : ms + p]
    assert gap(sides[0].problem, y, z, TAU) > 1e-12


def test_proofs_leave_every_answers_verdict_as_it_was() -> None:
    """``x ≤ −δ/2`` and ``−x ≤ −δ/2``, infeasible by ``δ`` = 1e-7 < τ, after a feasible warm
    solve: DAQP finds it infeasible, and its iterate meets the rows within τ. Whether that
    answer passes the check depends on the multipliers it is judged with, which DAQP leaves
    as they were (the last answer's): DAQP's direction, read for the restart, is kept apart
    (a review found it judged with the direction, and accepted, where without proofs it was
    refused). With or without proofs: the same verdict, the same answer and multipliers."""
    pytest.importorskip("daqp")
    seen = []
    for refutes in (True, False):
        backend = make_backend("daqp")
        backend.refutes = refutes
        backend.solve(Problem(np.eye(1), np.zeros(1), G=ROWS, h=np.array([-5.0, 10.0]))).require()
        got = backend.solve(Problem(np.eye(1), np.zeros(1), G=ROWS, h=np.full(2, -0.5e-7)))
        seen.append((got.found, got.status, got.retried, got.x.tolist(), got.z.tolist()))
    assert seen[0] == seen[1]


ROWS = np.array([[1.0], [-1.0]])


def test_nothing_is_read_where_daqp_eliminated_the_equalities() -> None:
    """With ``eq_reduction = 1`` DAQP solves a reduced problem and its workspace describes
    that one: no direction is read (``ray`` stays zero) and the restart solves."""
    pytest.importorskip("daqp")
    backend = make_backend("daqp", eq_reduction=1)
    ws = Drift(seed=8)
    backend.solve(ws.problem).require()
    if backend._c is None:
        pytest.skip("the installed daqp's layout is not mirrored: no compiled restart")
    ws.move(0.01)
    made_infeasible(ws, "row past the box", 0.5, 8)
    refused = backend.solve(ws.problem)
    assert refused.refusal == "infeasible" and refused.iterations > 0
    assert not backend._c.ray.any()
