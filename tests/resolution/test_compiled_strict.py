"""The strict QP's warm attempt made inside compiled code (``QPSolver._strict_solve`` with
``RowDropping.compiled_attempt`` over DAQP's C functions) against the backend's own ``solve``.

A run whose steps take that path must be the very run whose steps call ``solve`` (a watcher
of the backend calls turns the path off): the same joint motion bit for bit, the same
statuses, iterations, refusals and accuracy, on scenes with refused strict problems
(relaxed steps, the cold retries after them) and with time-scaled ones.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import dvqp
from dvqp.resolution import qp
from dvqp.step import stages
from tests.runs import SCENES as SCENE_FILES

pytest.importorskip("daqp")
from solvers import daqp_abi
from solvers.daqp_c import solve_dropped

needs_mirror = pytest.mark.skipif(
    not daqp_abi.available(), reason="the installed daqp's layout is not mirrored"
)

SCENES = ("paper-two-inlets", "probe-into-clamp", "weld-rush", "joint-limit")


def run(scene: dvqp.Scene, monkeypatch: pytest.MonkeyPatch, *, compiled: bool) -> tuple[Any, int]:
    """The DAQP run, and how many calls made a backend's attempt in compiled code (the step's
    own, :func:`dvqp.step.stages.resolve_move`, and the resolver's)."""
    made = 0

    def counted(kernel: Any) -> Any:
        def call(*args: Any) -> Any:
            nonlocal made
            made += 1
            return kernel(*args)

        return call

    with monkeypatch.context() as patch:
        patch.setattr(qp, "solve_dropped", counted(solve_dropped))
        patch.setattr(stages, "resolve_move", counted(stages.resolve_move))
        watch = None if compiled else (lambda step, kind, problem, solution: None)
        return dvqp.plan(scene, "daqp", watch=watch), made


@needs_mirror
@pytest.mark.parametrize("name", SCENES)
def test_a_run_in_compiled_code_is_the_run_through_solve(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = dvqp.load_scene(str(SCENE_FILES / f"{name}.toml"))
    fast, made = run(scene, monkeypatch, compiled=True)
    slow, none = run(scene, monkeypatch, compiled=False)
    assert made > 0.3 * fast.n_steps and none == 0  # with a watcher, every call is solve's
    np.testing.assert_array_equal(fast.q, slow.q)
    np.testing.assert_array_equal(fast.qdot, slow.qdot)
    assert list(fast.status) == list(slow.status)
    assert list(fast.iterations) == list(slow.iterations)
    assert fast.refusals == slow.refusals
    assert fast.accuracy == slow.accuracy


@pytest.mark.parametrize("name", ["paper-two-inlets", "fold"])
def test_a_baseline_run_in_one_call_a_step_is_the_run_through_resolve(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The baseline's step and move made in one compiled call
    (:func:`dvqp.step.stages.resolve_move_baseline`) against :meth:`Stepper.resolve` then
    :meth:`Stepper.move`."""
    from dvqp.step.engine import Stepper

    scene = dvqp.load_scene(str(SCENE_FILES / f"{name}.toml"))
    made = 0
    kernel = stages.resolve_move_baseline

    def counted(*args: Any) -> Any:
        nonlocal made
        made += 1
        return kernel(*args)

    with monkeypatch.context() as patch:
        patch.setattr(stages, "resolve_move_baseline", counted)
        fast = dvqp.plan(scene, "pinv")
    with monkeypatch.context() as patch:
        patch.setattr(Stepper, "_baseline_move", lambda self, c, dt: (self.resolve(c, dt), None))
        slow = dvqp.plan(scene, "pinv")
    assert made > 0.9 * fast.n_steps  # all but a stop's steps
    np.testing.assert_array_equal(fast.q, slow.q)
    np.testing.assert_array_equal(fast.qdot, slow.qdot)
    np.testing.assert_array_equal(fast.limit_excess, slow.limit_excess)
    assert list(fast.status) == list(slow.status)
