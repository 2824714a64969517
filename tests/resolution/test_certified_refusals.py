"""Strict refusals proved without a solve (``solvers.farkas``) in a run's relaxed or slowed
streak: the multipliers of the step's relaxed or time-scaled answer, held by the strict
backend (``solvers.daqp_c.hold_multipliers``), prove the next step's strict problem
infeasible. A refusal so proved is one that no answer could have escaped: the run is the run
that solves every strict problem, bit for bit."""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np
import pytest

import dvqp
from dvqp.motion import follow
from dvqp.resolution.qp import QPSolver
from dvqp.workspace import as_struct
from solvers import daqp_c
from solvers.daqp_ import DaqpBackend
from solvers.daqp_c import AttemptCall, hold_multipliers
from solvers.jit import njit
from solvers.rows import AttemptRows
from tests.motion.test_follow import assert_same_run
from tests.runs import SCENES

daqp = pytest.importorskip("daqp")


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


@pytest.mark.parametrize(("name", "kind"), [("joint-limit", "relaxed"), ("weld-rush", "slowed")])
def test_refusals_proved_without_a_solve_leave_the_run_bitwise_as_solving_them(
    name: str, kind: str
) -> None:
    """In the loop most strict problems of a streak are proved infeasible (the first of each
    streak is solved); the run is the one that solves them all, and the one taken step by
    step in Python (which holds no multipliers: it proves none but from what DAQP left)."""
    solving, none = flags_of_a_run(name, refutes=False, loop=True)
    proving, flags = flags_of_a_run(name, refutes=True, loop=True)
    stepwise, _ = flags_of_a_run(name, refutes=True, loop=False)
    refused = int(np.sum(solving.status == kind))
    assert refused > 100 and daqp_c.CERTIFIED not in none
    assert flags[daqp_c.CERTIFIED] > 0.8 * refused
    assert_same_run(proving, solving)
    assert_same_run(stepwise, solving)
    assert solving.refusals == proving.refusals == {"infeasible": refused}


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
