"""Strict refusals proved without a solve (``solvers.farkas``) in a run's relaxed or slowed
streak: the multipliers the strict backend holds (``solvers.daqp_c.hold_multipliers``: the
least-violation problem's, ``dvqp.resolution.ray``, or the relaxed or time-scaled answer's)
prove the next steps' strict problems infeasible. A refusal so proved is one no answer could
have escaped: the run's steps are those of the run that solves every strict problem, bit for
bit; only the work recorded differs where a step counts its refusal's iterations (levels)."""

from __future__ import annotations

import itertools
from collections import Counter
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import dvqp
import solvers
from dvqp.motion import follow
from dvqp.resolution.levels import load_relaxed
from dvqp.resolution.qp import QPSolver
from dvqp.resolution.ray import ray_constants, ray_problem
from dvqp.workspace import as_struct
from solvers import daqp_c
from solvers.daqp_ import DaqpBackend
from solvers.daqp_c import AttemptCall, hold_multipliers
from solvers.jit import njit
from solvers.rows import AttemptRows
from tests.motion.test_follow import assert_same_run
from tests.oracles.farkas import proves
from tests.runs import SCENES

daqp = pytest.importorskip("daqp")
TOLERANCE = DaqpBackend.default_tolerance


def flags_of_a_run(name: str, refutes: bool, loop: bool) -> tuple[Any, Counter[float]]:
    """The DAQP run of scene ``name`` and the exit flags of the strict refusals its compiled
    loop counted (its relaxed or slowed steps': ``QPSolver.count_refused``)."""
    scene = dvqp.load_scene(str(SCENES / f"{name}.toml"))
    flags: Counter[float] = Counter()
    count = QPSolver.count_refused

    def counted(self: QPSolver, refused: np.ndarray) -> None:
        flags.update(refused.tolist())
        count(self, refused)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(DaqpBackend, "refutes", refutes)
        patch.setattr(QPSolver, "count_refused", counted)
        patch.setattr(follow, "COMPILE", "always" if loop else "never")
        if not loop:
            patch.setattr(follow, "ready", lambda kernel, args: False)
        return dvqp.plan(scene, "daqp"), flags


@pytest.mark.parametrize(
    ("name", "kind", "least"),
    [("joint-limit", "relaxed", 100), ("weld-rush", "slowed", 100), ("fold", "relaxed", 10)],
)
def test_refusals_proved_without_a_solve_leave_the_run_bitwise_as_solving_them(
    name: str, kind: str, least: int
) -> None:
    """In the loop nearly every strict problem of a streak is proved infeasible, its first
    one's too (by the least-violation problem's multipliers, solved instead of the cold
    restart); the run is the one that solves them all, and the one taken step by step in
    Python (which holds no multipliers: it proves none but from what DAQP left)."""
    solving, none = flags_of_a_run(name, refutes=False, loop=True)
    proving, flags = flags_of_a_run(name, refutes=True, loop=True)
    stepwise, _ = flags_of_a_run(name, refutes=True, loop=False)
    refused = int(np.sum(solving.status == kind))
    assert refused > least and daqp_c.CERTIFIED not in none
    assert flags[daqp_c.CERTIFIED] > 0.8 * refused
    assert_same_run(proving, solving)
    assert_same_run(stepwise, solving)
    assert solving.refusals == proving.refusals
    assert set(solving.refusals) == {"infeasible"} and solving.refusals["infeasible"] >= refused


def attempt_rows(
    row_of: list[int], rows: int, ms: int, m: int, lam: list[float]
) -> tuple[Any, np.ndarray]:
    """A packed :class:`AttemptRows` whose copy holds ``row_of`` (slot → row, −1 free) of a
    problem of ``rows`` inequality rows, and its call's ``lam`` (laid out ``[box (ms), slots,
    m]``)."""
    p = len(row_of)
    slot_of = np.full(rows, -1, np.int64)
    for slot, row in enumerate(row_of):
        if row >= 0:
            slot_of[row] = slot
    n, empty = 2, np.zeros(0)
    call = AttemptCall(
        *(np.zeros((0, n)), empty) * 3,
        empty,
        empty,
        np.zeros(4),
        np.zeros(4, np.int64),
        np.zeros(4, np.int64),
        n,
        p,
        m,
        ms,
        0,
        np.zeros(1, np.int64),
        1e-6,
        1e-6,
        np.zeros(n),
        np.array(lam, float),
        np.zeros(len(lam)),
    )
    packed = as_struct(
        AttemptRows(
            np.zeros((rows, n)),
            np.zeros(rows),
            slot_of,
            np.array(row_of, np.int64),
            np.zeros((rows, n)),
            np.zeros(rows),
            p,
            call,
        )
    )
    return packed, call.lam


@njit
def hold(source: Any, target: Any) -> None:
    """:func:`hold_multipliers` from compiled code, as its callers call it."""
    hold_multipliers(source, target)


def test_held_multipliers_move_from_slot_to_slot_through_their_rows() -> None:
    """Rows 0..3: the source's copy holds rows 2, 0, 3 (a free slot between), the target's
    rows 1, 3, 0, 2 (row 1 without a source slot: 0); the equality rows' as they are; the
    target's bounds' untouched."""
    source, _ = attempt_rows([2, 0, -1, 3], 4, 3, 2, [9, 9, 9, 0.2, 0.0, 7.0, 0.3, -5.0, 6.0])
    target, lam = attempt_rows([1, 3, 0, 2], 4, 2, 2, [-1, -1, 8, 8, 8, 8, 8, 8])
    hold(source, target)
    np.testing.assert_array_equal(lam, [-1, -1, 0.0, 0.3, 0.0, 0.2, -5.0, 6.0])
    other, _ = attempt_rows([0], 4, 2, 1, [0, 0, 4.0, 1.0])  # one equality row: not the same
    hold(other, target)
    np.testing.assert_array_equal(lam, [-1, -1, 0.0, 0.3, 0.0, 0.2, -5.0, 6.0])


def test_the_least_violation_proves_a_slight_violation_that_the_relaxed_answer_does_not() -> None:
    """fold's strict task is violated slightly in its streaks: the relaxed answer's
    multipliers carry the step's cost gradient and prove hardly any of its strict problems
    infeasible; those of the least-violation problem (no cost) prove every one, on the strict
    problem's own data (checked here by the NumPy oracle of the proof)."""
    scene = dvqp.load_scene(str(SCENES / "fold.toml"))
    seen: list[tuple[str, Any, Any]] = []

    def watch(step: int, kind: str, problem: Any, solution: Any) -> None:
        arrays = {k: np.array(getattr(problem, k)) for k in ("P", "q", "A", "b", "G", "h")}
        arrays.update(lb=np.array(problem.lb), ub=np.array(problem.ub))
        seen.append((kind, SimpleNamespace(**arrays), solution))

    dvqp.plan(scene, "daqp", watch=watch)
    pairs = [
        (strict, relaxed)
        for (kind, strict, refused), (then, _, relaxed) in itertools.pairwise(seen)
        if kind == "strict" and not refused.found and then == "relaxed" and relaxed.found
    ]
    assert len(pairs) >= 10
    backend, by_relaxed = solvers.make_backend("daqp"), 0
    for strict, relaxed in pairs:
        n = strict.lb.shape[0]
        qp = SimpleNamespace(cost=strict.q, P=strict.P, A=strict.A, b=strict.b, G=strict.G)
        qp.h, qp.lb, qp.ub = strict.h, strict.lb, strict.ub
        ray = ray_problem(qp)
        load_relaxed(qp, ray, *ray_constants(n))
        least = backend.solve(ray).require()
        assert np.abs(least[n:]).max() > 1e-4  # the task's least violation
        answer = backend.solve(ray)
        assert proves(strict, answer.y, answer.z, TOLERANCE)
        by_relaxed += proves(strict, relaxed.y, relaxed.z, TOLERANCE)
    assert by_relaxed < 0.2 * len(pairs)


def test_levels_proving_refusals_take_the_same_steps_and_count_the_work_saved() -> None:
    """reach-priorities' relaxed steps count their strict refusal's iterations with their own
    (as the levels' cascade counts them): where the loop proves a refusal, that step records
    fewer; its steps, statuses and refusals are those of the run that solves every one, and
    of the run step by step in Python."""
    solving, _ = flags_of_a_run("reach-priorities", refutes=False, loop=True)
    proving, flags = flags_of_a_run("reach-priorities", refutes=True, loop=True)
    stepwise, _ = flags_of_a_run("reach-priorities", refutes=True, loop=False)
    relaxed = solving.status == "relaxed"
    assert int(relaxed.sum()) > 100 and flags[daqp_c.CERTIFIED] > 0.8 * int(relaxed.sum())
    for name in ("q", "qdot", "tool", "task_error", "level_error", "min_clearance"):
        np.testing.assert_array_equal(getattr(proving, name), getattr(solving, name), name)
    assert list(proving.status) == list(solving.status)
    assert proving.refusals == solving.refusals == {"infeasible": int(relaxed.sum())}
    assert np.all(proving.iterations <= solving.iterations)
    assert np.sum(proving.iterations[relaxed]) < 0.8 * np.sum(solving.iterations[relaxed])
    np.testing.assert_array_equal(proving.iterations[~relaxed], solving.iterations[~relaxed])
    assert_same_run(stepwise, proving)
