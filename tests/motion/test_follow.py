"""A run's compiled loop (:mod:`dvqp.motion.follow`) against the same run step by step.

The loop takes a run's common steps in compiled code and hands every other step to Python.
With it or without it (``Stepper.fused`` returning None turns it off), a run must be the same
run: the same samples and steps bit for bit, the same progress calls, the same accuracy and
refusals. The schedule's command, which the loop and Python read through one compiled
function, is checked here against the formula written out in NumPy.
"""

from __future__ import annotations

import dataclasses
import importlib
import itertools
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dvqp
from dvqp.limits import AccelerationLimit
from dvqp.motion import follow
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.schedule import Schedule
from dvqp.step.engine import Stepper
from tests.runs import SCENES as SCENE_FILES

SAMPLES = (
    "q",
    "qdot",
    "tool",
    "w",
    "task_error",
    "level_error",
    "limit_excess",
    "min_clearance",
    "path_time",
    "iterations",
    "substeps",
)


@pytest.fixture(autouse=True)
def loop_compiles(monkeypatch: pytest.MonkeyPatch) -> None:
    """Each run here compiles its loop (a cold process would leave a first run in Python)."""
    monkeypatch.setattr(follow, "COMPILE", "always")


def planned(name: str, backend: str, loop: bool, **options: Any) -> tuple[Any, list, int]:
    """The run, its progress calls and the steps the loop took."""
    scene = dvqp.load_scene(str(SCENE_FILES / f"{name}.toml"))
    calls: list[tuple[int, int]] = []
    taken = 0
    kernels = follow.follow, follow.follow_baseline

    def counted(kernel: Any, at: int) -> Any:
        def call(*args: Any) -> Any:
            nonlocal taken
            out = kernel(*args)
            taken += int(out[1]) - args[at]
            return out

        return call

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(follow, "follow", counted(kernels[0], 5))
        patch.setattr(follow, "follow_baseline", counted(kernels[1], 3))
        if not loop:
            patch.setattr(Stepper, "fused", lambda self: None)
        traj = dvqp.plan(scene, backend, progress=lambda k, n: calls.append((k, n)), **options)
    return traj, calls, taken


def assert_same_run(a: Any, b: Any) -> None:
    for name in SAMPLES:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert list(a.status) == list(b.status)
    assert a.refusals == b.refusals
    assert a.accuracy == b.accuracy


@pytest.mark.parametrize(
    ("name", "backend"),
    [
        ("paper-two-inlets", "daqp"),  # two relaxed steps
        ("weld-rush", "daqp"),  # time-scaled, slowed steps handed over, the recorder grows
        ("weld-rush", "pinv"),
        ("fold", "daqp"),
        ("reach-priorities", "daqp"),  # two levels, met together in most steps
    ],
)
def test_a_run_with_its_compiled_loop_is_the_run_step_by_step(name: str, backend: str) -> None:
    fast, fast_calls, taken = planned(name, backend, loop=True)
    slow, slow_calls, none = planned(name, backend, loop=False)
    assert none == 0 and taken > 0.5 * fast.n_steps
    assert_same_run(fast, slow)
    assert fast_calls == slow_calls  # one progress call a step, the same counts
    assert len(fast_calls) >= fast.n_steps - 100  # a stop's steps are not counted


@pytest.mark.parametrize(
    ("name", "kind", "python"),
    [
        ("probe-into-clamp", "relaxed", 1),
        ("weld-rush", "slowed", 2),
        ("reach-priorities", "relaxed", 1),
    ],
)
def test_a_refused_streak_runs_in_the_loop_and_each_handed_step_is_finished_by_python(
    name: str, kind: str, python: int
) -> None:
    """probe-into-clamp relaxes hundreds of steps in one streak, weld-rush slows 171 in
    three, reach-priorities relaxes 193 (its levels together refused, the last level relaxed
    with the first held: the first QP of their cascade): a streak's first step (the warm
    strict attempt refused, restarted cold) and the others (the cold attempt refused) are the
    loop's, relaxed or slowed there; the first slowed step of a run too, but for its
    time-scaled backend's set-up (the relaxed backend is set up before the run's steps).
    With a stride of 0 the loop hands every step over after its move (with every attempt
    made, and a slowed step's ``b`` put back): Python finishes each as it would have made
    it."""
    fast, _, taken = planned(name, "daqp", loop=True)
    slow, _, _ = planned(name, "daqp", loop=False)
    refused = int(np.sum(fast.status == kind))
    # Python's: the first step (the backends' set-up), a run's first slowed step (the
    # time-scaled backend's set-up) and a stop's steps
    assert refused > 100 and taken == fast.brake_start - python
    assert fast.refusals == {"infeasible": refused}
    assert_same_run(fast, slow)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(follow, "JOINT_STRIDE", 0.0)
        handed, _, none = planned(name, "daqp", loop=True)
    assert none == 0
    assert_same_run(handed, slow)


def test_a_recorder_outgrown_inside_the_loop_is_grown_and_the_loop_goes_on() -> None:
    """weld-rush without its stop has no room reserved beyond its nominal steps, and its
    slowed steps take more: the loop stops at the room's end, the recorder grows, and the
    loop writes into the new arrays."""
    grown = 0
    extend = TrajectoryRecorder.extend

    def counted(self: TrajectoryRecorder, steps: int) -> None:
        nonlocal grown
        grown += 1
        extend(self, steps)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(TrajectoryRecorder, "extend", counted)
        fast, _, taken = planned("weld-rush", "daqp", loop=True, stop=False)
        assert grown == 1
        slow, _, _ = planned("weld-rush", "daqp", loop=False, stop=False)
    assert taken > 0.5 * fast.n_steps
    assert_same_run(fast, slow)


@pytest.mark.parametrize(
    ("policy", "first_step_compiled", "cached", "long", "looped"),
    [
        ("warm", True, False, False, False),  # the first run after installing: in Python
        ("warm", False, False, False, True),  # the next run compiles the loop
        ("warm", True, True, False, True),  # a loop in the cache is loaded, whatever compiled
        ("warm", True, False, True, True),  # a long run compiles it
        ("never", False, False, True, False),
        ("never", True, True, False, True),
        ("always", True, False, False, True),
    ],
)
def test_a_run_compiles_its_loop_as_the_policy_says_and_is_the_same_run_either_way(
    policy: str, first_step_compiled: bool, cached: bool, long: bool, looped: bool
) -> None:
    """:data:`dvqp.motion.follow.COMPILE`: ``"warm"`` compiles the loop in a run whose first
    step compiled nothing, or a long one (:data:`~dvqp.motion.follow.LONG_RUN` steps); a loop
    the cache holds is always taken (``ready``)."""
    simulate = importlib.import_module("dvqp.motion.simulate")
    counted = itertools.count(0, 1 if first_step_compiled else 0)
    asked: list[Any] = []

    def in_cache(kernel: Any, args: tuple[Any, ...]) -> bool:
        asked.append(kernel)
        return cached

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(follow, "COMPILE", policy)
        patch.setattr(simulate, "compiled_count", lambda: next(counted))
        patch.setattr(follow, "ready", in_cache)
        patch.setattr(follow, "LONG_RUN", 700 if long else 800)  # the run: 760 steps
        run, calls, taken = planned("paper-two-inlets", "daqp", loop=True)
    assert run.n_steps > 700 and run.brake_start < 800
    assert (taken > 0.5 * run.n_steps) if looped else taken == 0
    may_compile = policy == "always" or (policy == "warm" and (long or not first_step_compiled))
    # asked when the loop's arguments change (the relaxed backend set up), not every call
    assert not asked if may_compile else 1 <= len(asked) <= 3
    slow, slow_calls, _ = planned("paper-two-inlets", "daqp", loop=False)
    assert_same_run(run, slow)
    assert calls == slow_calls


class Counting(AccelerationLimit):
    """An acceleration limit that observes in Python (and counts it)."""

    def observe(self, qdot: np.ndarray, dt: float) -> None:
        self.seen = getattr(self, "seen", 0) + 1
        super().observe(qdot, dt)


def test_a_limit_that_observes_in_python_turns_the_loop_off_and_sees_every_step() -> None:
    scene = dvqp.load_scene(str(SCENE_FILES / "paper-two-inlets.toml"))
    (accel,) = [x for x in scene.limits if isinstance(x, AccelerationLimit)]
    counting = Counting(scene.robot, accel.qdd_max)
    limits = tuple(counting if x is accel else x for x in scene.limits)
    assert counting.observed_into() is None
    assert accel.observed_into() is accel.previous
    taken = 0
    kernel = follow.follow

    def counted(s: Any, w: Any, r: Any, p: Any, f: Any, k: int, *rest: Any) -> Any:
        nonlocal taken
        out = kernel(s, w, r, p, f, k, *rest)
        taken += int(out[1]) - k
        return out

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(follow, "follow", counted)
        seen = dvqp.plan(dataclasses.replace(scene, limits=limits), "daqp")
        assert taken == 0
        looped = dvqp.plan(scene, "daqp")
        assert taken > 0.5 * looped.n_steps
    assert counting.seen >= seen.n_steps
    assert_same_run(seen, looped)


def dv_error_oracle(reference: np.ndarray, actual: np.ndarray, radius: float) -> np.ndarray:
    """``x_d − x`` with l and α wrapped to the nearest period (written out here)."""
    e = reference - actual
    for c, period in ((0, 2.0 * math.pi * radius), (3, 2.0 * math.pi)):
        e[c] = e[c] - period * np.floor(e[c] / period + 0.5)
    return e


finite = st.floats(-50.0, 50.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    u=st.floats(0.0, 4.999, allow_nan=False),
    tool=st.lists(finite, min_size=4, max_size=4),
    gain=st.floats(0.0, 20.0),
    scaled=st.booleans(),
)
def test_the_schedule_command_is_the_feedforward_plus_the_wrapped_feedback(
    seed: int, u: float, tool: list[float], gain: float, scaled: bool
) -> None:
    rng = np.random.default_rng(seed)
    reference = np.cumsum(rng.normal(size=(6, 4)), axis=0)
    dt, radius = 0.05, 0.3
    commands = np.diff(reference, axis=0) / dt
    x = np.array(tool)
    schedule = Schedule(commands, reference[:-1], gain, dt, radius, scaled=scaled)
    xdot, feedforward, span = schedule.command(u, x)
    if scaled:  # the path's nodes: the reference, then its last plus the last command's motion
        nodes = np.vstack([reference[:-1], reference[-2] + dt * commands[-1]])
        span_expected = min(1.0, 5 - u)

        def at(v: float) -> np.ndarray:
            i = min(int(v), 4)
            return nodes[i] + (v - i) * (nodes[i + 1] - nodes[i])

        here = at(u)
        expected_ff = (at(u + span_expected) - here) / dt
        assert span == span_expected
        assert feedforward is not None
        np.testing.assert_array_equal(feedforward, expected_ff)
        expected = expected_ff + gain * dv_error_oracle(here, x, radius)
    else:
        k = int(u)
        assert span == 1.0 and feedforward is None
        expected = commands[k].copy()
        if gain > 0.0:
            expected = expected + gain * dv_error_oracle(reference[k], x, radius)
    np.testing.assert_allclose(xdot, expected, rtol=1e-12, atol=1e-9)
    assert np.all(np.isfinite(xdot))
