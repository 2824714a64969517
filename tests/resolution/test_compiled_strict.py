"""The strict QP's warm attempt made inside compiled code (``QPSolver._strict_solve`` with
``RowDropping.compiled_attempt`` over DAQP's C functions) against the backend's own ``solve``.

A run whose steps take that path must be the very run whose steps call ``solve`` (a watcher
of the backend calls turns the path off): the same joint motion bit for bit, the same
statuses, iterations, refusals and accuracy, on scenes with refused strict problems
(relaxed steps, the cold retries after them) and with time-scaled ones.
"""

from __future__ import annotations

import importlib
from typing import Any

import numpy as np
import pytest

import dvqp
from dvqp.motion import follow
from dvqp.resolution import qp
from dvqp.step import stages
from dvqp.step.engine import Stepper
from tests.runs import SCENES as SCENE_FILES

pytest.importorskip("daqp")
from solvers import daqp_abi
from solvers.daqp_c import solve_dropped

simulation = importlib.import_module("dvqp.motion.simulate")  # the package exports the function
needs_mirror = pytest.mark.skipif(
    not daqp_abi.available(), reason="the installed daqp's layout is not mirrored"
)


@pytest.fixture(autouse=True)
def loop_compiles(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each run here compiles its loop (a cold process would leave a first run in Python)."""
    monkeypatch.setattr(follow, "COMPILE", "always")


SCENES = ("paper-two-inlets", "probe-into-clamp", "weld-rush", "joint-limit", "reach-priorities")


def run(scene: dvqp.Scene, monkeypatch: pytest.MonkeyPatch, mode: str) -> tuple[Any, int]:
    """The DAQP run and how many of its steps made the strict attempt in compiled code.

    ``mode``: ``"loop"`` as a run goes (its common steps in the compiled loop,
    :mod:`dvqp.motion.follow`: counted as the steps it took, and the steps it hands over);
    ``"step"`` one compiled call a step (:func:`dvqp.step.stages.resolve_move` from Python,
    the loop turned off; counted with the resolver's own compiled attempts); ``"solve"``
    every call the backend's ``solve`` (a watcher of the backend calls turns both off).
    Counted from the run's first step: the calls of the run's compile before it are not the
    run's (nor shown to its watcher)."""
    made = 0
    compiled = simulation._compiled

    def from_first_step(*args: Any) -> None:
        nonlocal made
        compiled(*args)
        made = 0

    def counted(kernel: Any) -> Any:
        def call(*args: Any) -> Any:
            nonlocal made
            made += 1
            return kernel(*args)

        return call

    def looped(kernel: Any) -> Any:
        def call(s: Any, w: Any, r: Any, p: Any, f: Any, k: int, *rest: Any) -> Any:
            nonlocal made
            out = kernel(s, w, r, p, f, k, *rest)
            made += int(out[1]) - k + int(out[0] == follow.HANDED)
            return out

        return call

    with monkeypatch.context() as patch:
        patch.setattr(qp, "solve_dropped", counted(solve_dropped))
        patch.setattr(stages, "resolve_move", counted(stages.resolve_move))
        patch.setattr(follow, "follow", looped(follow.follow))
        patch.setattr(simulation, "_compiled", from_first_step)
        if mode != "loop":
            patch.setattr(Stepper, "fused", lambda self: None)
        watch = (lambda step, kind, problem, solution: None) if mode == "solve" else None
        return dvqp.plan(scene, "daqp", watch=watch), made


@needs_mirror
@pytest.mark.parametrize("name", SCENES)
def test_a_run_in_compiled_code_is_the_run_through_solve(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = dvqp.load_scene(str(SCENE_FILES / f"{name}.toml"))
    slow, none = run(scene, monkeypatch, "solve")
    assert none == 0  # with a watcher, every call is solve's
    for mode in ("loop", "step"):
        fast, made = run(scene, monkeypatch, mode)
        assert made > 0.3 * fast.n_steps, mode
        np.testing.assert_array_equal(fast.q, slow.q)
        np.testing.assert_array_equal(fast.qdot, slow.qdot)
        np.testing.assert_array_equal(fast.task_error, slow.task_error)
        np.testing.assert_array_equal(fast.limit_excess, slow.limit_excess)
        np.testing.assert_array_equal(fast.path_time, slow.path_time)
        assert list(fast.status) == list(slow.status)
        assert list(fast.iterations) == list(slow.iterations)
        assert list(fast.substeps) == list(slow.substeps)
        assert fast.refusals == slow.refusals
        assert fast.accuracy == slow.accuracy


@pytest.mark.parametrize("name", ["paper-two-inlets", "fold", "weld-rush"])
def test_a_baseline_run_in_one_call_a_step_is_the_run_through_resolve(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The baseline's steps in the compiled loop (:func:`dvqp.motion.follow.follow_baseline`,
    each step and move one call, :func:`dvqp.step.stages.resolve_move_baseline`) against
    :meth:`Stepper.resolve` then :meth:`Stepper.move` from Python."""
    scene = dvqp.load_scene(str(SCENE_FILES / f"{name}.toml"))
    made = 0
    kernel = follow.follow_baseline

    def counted(s: Any, clock: int, f: Any, k: int, *rest: Any) -> Any:
        nonlocal made
        out = kernel(s, clock, f, k, *rest)
        made += int(out[1]) - k
        return out

    with monkeypatch.context() as patch:
        patch.setattr(follow, "follow_baseline", counted)
        fast = dvqp.plan(scene, "pinv")
    with monkeypatch.context() as patch:
        patch.setattr(Stepper, "fused", lambda self: None)
        patch.setattr(
            Stepper,
            "resolve_and_move",
            lambda self, c, dt, made=None: (self.resolve(c, dt), None),
        )
        slow = dvqp.plan(scene, "pinv")
    assert made > 0.9 * fast.n_steps  # all but a stop's steps
    np.testing.assert_array_equal(fast.q, slow.q)
    np.testing.assert_array_equal(fast.qdot, slow.qdot)
    np.testing.assert_array_equal(fast.limit_excess, slow.limit_excess)
    np.testing.assert_array_equal(fast.task_error, slow.task_error)
    np.testing.assert_array_equal(fast.path_time, slow.path_time)
    assert list(fast.status) == list(slow.status)
