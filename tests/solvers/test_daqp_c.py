"""DAQP's C functions called from compiled code (``solvers.daqp_c``) against ``daqp.Model``.

The two ways to DAQP make the same calls in the same order: every answer, multiplier,
iteration count and status must be bitwise the same, warm, restarted, after ``P`` changed,
from a primal start and when the set-up fails.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from solvers import Problem, Solution, make_backend
from solvers.stateful import solve_guarded
from tests.solvers.test_daqp_fast import FIELDS, Drift

daqp = pytest.importorskip("daqp")
from solvers import daqp_abi  # noqa: E402  (after the skip: it reads daqp's version)
from solvers.daqp_ import DaqpBackend  # noqa: E402

needs_mirror = pytest.mark.skipif(
    not daqp_abi.available(), reason="the installed daqp's layout is not mirrored"
)


@pytest.fixture(autouse=True)
def restarts_solve(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every restart solves: ``daqp.Model`` has no compiled restart, so it cannot prove a
    refusal from held multipliers without a solve as the C way may
    (``DaqpBackend.refutes``, tested in ``tests/solvers/test_farkas.py``)."""
    monkeypatch.setattr(DaqpBackend, "refutes", False)


@pytest.fixture
def by_model(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """``solve(backend, problem, how=None)`` with the C functions disabled: daqp.Model."""

    def solve(backend: Any, problem: Problem, how: str | None = None) -> Solution:
        with monkeypatch.context() as patch:
            patch.setattr(daqp_abi, "available", lambda: False)
            return call(backend, problem, how)

    yield solve


def call(backend: Any, problem: Problem, how: str | None = None) -> Solution:
    """``backend.solve(problem)``, or one of its paths by name (``"restart"``)."""
    if how == "restart":
        return solve_guarded(backend, problem, backend._restart, problem, None)
    return backend.solve(problem)


def assert_same(got: Solution, want: Solution) -> None:
    for name in ("found", "status", "iterations", "message", "retried"):
        assert getattr(got, name) == getattr(want, name), name
    for name in ("x", "y", "z", "z_box"):
        a, b = getattr(got, name), getattr(want, name)
        assert (a is None) == (b is None), name
        if a is not None:
            np.testing.assert_array_equal(a, b, err_msg=name)


@needs_mirror
def test_the_installed_daqp_is_mirrored_and_solves_through_its_c_functions() -> None:
    assert importlib.metadata.version("daqp") in daqp_abi.KNOWN_VERSIONS
    backend = make_backend("daqp")
    backend.solve(Drift(seed=1).problem).require()
    assert backend._c is not None and backend._model is None


@needs_mirror
def test_compiled_calls_give_daqp_models_answers_bitwise(by_model: Any) -> None:
    c_side, model_side = Drift(seed=11), Drift(seed=11)
    in_c, in_model = make_backend("daqp"), make_backend("daqp")
    for step in range(40):
        size = 0.3 if step % 10 == 9 else 0.02
        c_side.move(size)
        model_side.move(size)
        if step in (5, 17):  # a new P: H factored again
            c_side.P[:] += np.eye(c_side.P.shape[0])
            model_side.P[:] += np.eye(model_side.P.shape[0])
        how = "restart" if step in (8, 25) else None
        got = call(in_c, c_side.problem, how)
        want = by_model(in_model, model_side.problem, how)
        assert_same(got, want)
        assert got.found, got.message
    assert in_c._c is not None and in_model._model is not None


@needs_mirror
@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(min_value=0, max_value=2**32 - 1),
    sizes=st.lists(st.sampled_from([0.0, 0.005, 0.05, 0.5]), min_size=4, max_size=12),
    rows=st.integers(min_value=0, max_value=12),
)
def test_any_drift_is_solved_bitwise_as_daqp_model(
    seed: int, sizes: list[float], rows: int
) -> None:
    c_side, model_side = Drift(seed=seed, p=rows), Drift(seed=seed, p=rows)
    in_c, in_model = make_backend("daqp"), make_backend("daqp")
    with pytest.MonkeyPatch.context() as patch:
        for size in sizes:
            c_side.move(size)
            model_side.move(size)
            got = in_c.solve(c_side.problem)
            patch.setattr(daqp_abi, "available", lambda: False)
            want = in_model.solve(model_side.problem)
            patch.undo()
            assert_same(got, want)


@needs_mirror
def test_a_primal_start_and_a_failed_set_up_are_daqp_models(by_model: Any) -> None:
    ws = Drift(seed=12)
    guess = np.linspace(-0.1, 0.1, ws.q.size)
    in_c, in_model = make_backend("daqp"), make_backend("daqp")
    assert_same(in_c.solve(ws.fresh(), guess), by_model_initvals(by_model, in_model, ws, guess))
    indefinite = {name: getattr(ws, name) for name in FIELDS}
    indefinite["P"] = -np.eye(ws.q.size)
    bad = Problem(**indefinite)
    failed_c, failed_model = make_backend("daqp").solve(bad), by_model(make_backend("daqp"), bad)
    assert not failed_c.found and failed_c.status == "setup failed: nonconvex"
    assert_same(failed_c, failed_model)
    again = make_backend("daqp")
    assert not again.solve(bad).found
    assert again.solve(ws.fresh()).found  # set up anew after the failure


def by_model_initvals(by_model: Any, backend: Any, ws: Drift, guess: np.ndarray) -> Solution:
    class WithGuess:
        def solve(self, problem: Problem) -> Solution:
            return backend.solve(problem, guess)

    return by_model(WithGuess(), ws.fresh())  # type: ignore[no-any-return]


@needs_mirror
def test_a_problem_the_compiled_copy_refuses_is_copied_with_numpy_bitwise(by_model: Any) -> None:
    c_side, model_side = Drift(seed=13), Drift(seed=13)
    problems = []
    for ws in (c_side, model_side):
        arrays = {name: getattr(ws, name) for name in FIELDS}
        arrays["G"] = ws.G_fortran = np.asfortranarray(ws.G)  # type: ignore[attr-defined]
        problems.append(Problem.trusted(**arrays))
    in_c, in_model = make_backend("daqp"), make_backend("daqp")
    for step in range(6):
        for ws in (c_side, model_side):
            ws.move(0.01)
            ws.G_fortran[:] = ws.G  # type: ignore[attr-defined]
            if step == 3:
                ws.P[:] *= 2.0
        got, want = in_c.solve(problems[0]), by_model(in_model, problems[1])
        assert_same(got, want)
        assert got.found and in_c._stack is None and in_c._c is not None


def test_an_unknown_daqp_version_keeps_daqp_model(monkeypatch: pytest.MonkeyPatch) -> None:
    daqp_abi._mirrored.cache_clear()
    try:
        monkeypatch.setattr(importlib.metadata, "version", lambda name: "0.0.1")
        assert not daqp_abi.available()
        backend = make_backend("daqp")
        assert backend.solve(Drift(seed=2).problem).found
        assert backend._model is not None and backend._c is None
        with pytest.raises(daqp_abi.LayoutError, match=r"0\.0\.1"):
            daqp_abi.Workspace(
                *(np.zeros(k) for k in (1, 1)),
                np.zeros((0, 1)),
                *(np.zeros(0),) * 2,
                np.zeros(0, np.intc),
                {},
            )
    finally:
        monkeypatch.undo()
        daqp_abi._mirrored.cache_clear()


@needs_mirror
def test_a_workspace_frees_once() -> None:
    ws = Drift(seed=3)
    backend = make_backend("daqp")
    backend.solve(ws.problem).require()
    work = backend._c
    backend.reset()  # closes it
    assert work is not None and work._work is None
    work.close()  # again: nothing to free


@needs_mirror
def test_a_workspace_laid_out_otherwise_is_refused_and_daqp_model_solves(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    fields = list(daqp_abi.WorkspaceHead._fields_)
    fields[1], fields[2] = fields[2], fields[1]  # n and m swapped: the check after set-up

    class Swapped(ctypes.Structure):
        _fields_ = fields

    monkeypatch.setattr(daqp_abi, "_MISMATCHED", [])
    monkeypatch.setattr(daqp_abi, "WorkspaceHead", Swapped)
    backend = make_backend("daqp")
    ws = Drift(seed=4)
    assert backend.solve(ws.problem).found
    assert backend._c is None and backend._model is not None
    assert not daqp_abi.available() and "name its problem" in daqp_abi._MISMATCHED[0]


def refusing_sequence(backend: Any) -> list[tuple[Any, ...]]:
    """Feasible, infeasible, feasible, infeasible: DAQP leaves its multipliers as they were
    when it has no answer, so a refusal's show what the buffers held."""
    n = 3
    P, q = np.eye(n) * 2.0, np.array([1.0, -1.0, 0.5])
    G = np.array([[1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [0.0, 1.0, 1.0]])
    h = np.ones(3)
    problem = Problem.trusted(P, q, None, None, G, h, None, None)
    seen = []
    for rows in ([1.0, 1.0, 1.0], [-1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [-2.0, 1.0, 1.0]):
        np.full(3, 1e300)  # memory that a fresh buffer could take over
        h[:] = rows
        s = backend.solve(problem)
        seen.append((s.found, s.status, s.retried, None if s.z is None else s.z.tolist()))
        seen.append(s.message)
    return seen


@needs_mirror
def test_a_refusals_multipliers_are_daqp_models(by_model: Any) -> None:
    in_c, in_model = make_backend("daqp"), make_backend("daqp")
    got = refusing_sequence(in_c)

    class ByModel:
        def solve(self, problem: Problem) -> Solution:
            return by_model(in_model, problem)  # type: ignore[no-any-return]

    assert got == refusing_sequence(ByModel())
    assert any(not found for found, *_ in got[::2])


@needs_mirror
def test_read_only_or_fortran_arrays_are_solved_not_packed() -> None:
    """A trusted problem may mix read-only and Fortran arrays: the compiled attempt declines
    them (None), and solve answers right."""
    from solvers.rows import RowDropping

    ws = Drift(seed=21)
    for name in ("q", "lb", "G"):
        arrays = {k: getattr(ws, k) for k in FIELDS}
        if name == "G":
            arrays[name] = np.asfortranarray(ws.G)
        else:
            arrays[name] = arrays[name].copy()
            arrays[name].flags.writeable = False
        problem = Problem.trusted(**arrays)
        backend = RowDropping(make_backend("daqp"))
        for _ in range(3):
            solution = backend.solve(problem)
            assert backend.compiled_attempt(problem) is None
            want = make_backend("daqp").solve(Problem(**arrays)).require()
            np.testing.assert_allclose(solution.require(), want, atol=2e-6)


@needs_mirror
def test_a_resolver_over_bare_daqp_backends_takes_the_python_path() -> None:
    from dvqp.resolution.qp import QPSolver
    from dvqp.workspace import QPBuffers

    qp = QPBuffers(
        P=np.eye(2),
        cost=np.zeros(2),
        A=np.array([[1.0, 1.0]]),
        b=np.array([1.0]),
        G=np.array([[1.0, 0.0]]),
        h=np.array([0.8]),
        lb=-np.ones(2),
        ub=np.ones(2),
    )
    solver = QPSolver(lambda: make_backend("daqp"), qp, task_weight=1e4)
    for step in range(4):
        qp.b[0] = 1.0 + 0.01 * step
        answer = solver.solve()
        assert answer.status == "optimal" and answer.x is not None
        assert abs(answer.x.sum() - qp.b[0]) < 1e-9


@needs_mirror
def test_settings_and_sizes_are_taken_as_daqp_model_takes_them() -> None:
    ws = Drift(seed=22)
    assert make_backend("daqp", iter_limit=1e4).solve(ws.problem).found  # a float, whole
    arrays = {k: getattr(ws, k) for k in FIELDS}
    arrays["lb"] = ws.lb[:1].copy()  # breaks the trusted contract: refused, not broadcast
    refused = make_backend("daqp").solve(Problem.trusted(**arrays))
    assert not refused.found and "do not fit" in refused.message


@needs_mirror
def test_a_workspace_is_neither_copied_nor_pickled() -> None:
    import copy
    import pickle

    backend = make_backend("daqp")
    backend.solve(Drift(seed=23).problem).require()
    for attempt in (copy.copy, copy.deepcopy, pickle.dumps):
        with pytest.raises(TypeError, match="DAQP workspace"):
            attempt(backend._c)


@needs_mirror
def test_the_compiled_check_follows_a_changed_tolerance() -> None:
    from solvers.rows import RowDropping

    ws = Drift(seed=24)
    backend = RowDropping(make_backend("daqp"))
    backend.solve(ws.problem).require()
    first = backend.compiled_attempt(ws.problem)
    assert first is not None and first.call.tolerance == 1e-6
    backend.inner.tolerance = 1e-3
    again = backend.compiled_attempt(ws.problem)
    assert again is not None and again.call.tolerance == 1e-3
