"""A task and a limit written by a user, each one class in a file outside the package.

The classes live in ``docs/examples/`` (the files docs/api.md shows) and reach the planner
through ``dvqp.plan(scene, backend, tasks=[...], limits=[...])``.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

import dvqp
from tests.common import PIPE_RADIUS, central_difference

EXAMPLES = Path(__file__).resolve().parent.parent / "docs" / "examples"
SCENE = Path(__file__).resolve().parent.parent / "scenes" / "paper-two-inlets.toml"


def load(name: str) -> ModuleType:
    spec = importlib.util.spec_from_file_location(f"user_{name}", EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def jog_scene(velocity: str, duration: float = 1.0) -> dvqp.Scene:
    text = SCENE.read_text(encoding="utf-8")
    start = text.index("[[motion.jog]]")
    jog = f"[[motion.jog]]\nduration = {duration}\nvelocity = {velocity}\n"
    return dvqp.scenes.loads(text[:start] + jog, "user.toml")


def test_the_tilt_row_is_the_derivative_of_the_tilt(robot: dvqp.Robot, q0: np.ndarray) -> None:
    tilt = load("tilt_task").TiltTask

    def cos_tilt(q: np.ndarray) -> float:
        return tilt.cos_tilt(dvqp.KinematicState.compute(robot, q, PIPE_RADIUS))[0]

    for q in (q0, q0 + 0.1, q0 - np.linspace(0, 0.2, 13)):
        state = dvqp.KinematicState.compute(robot, q, PIPE_RADIUS)
        np.testing.assert_allclose(
            tilt.cos_tilt(state)[1], central_difference(cos_tilt, q, 1e-7), atol=1e-7
        )


def test_a_user_tilt_task_turns_the_probe_while_the_tool_task_holds() -> None:
    pytest.importorskip("daqp")
    task = load("tilt_task").TiltTask(tilt=math.radians(30.0), gain=2.0, weight=100.0)
    scene = jog_scene("[0.0, 0.0, 0.0, 0.0]", duration=3.0)
    start = dvqp.KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius)
    before = math.degrees(math.acos(task.cos_tilt(start)[0]))
    traj = dvqp.plan(scene, "daqp", tasks=[task])
    end = dvqp.KinematicState.compute(scene.robot, traj.q[-1], scene.pipe_radius)
    after = math.degrees(math.acos(task.cos_tilt(end)[0]))
    assert abs(before - 30.0) > 10.0 and abs(after - 30.0) < 1.0
    assert traj.ok and traj.task_error.max() < 1e-9  # the hard DV task is untouched
    assert np.abs(traj.tool[-1] - traj.tool[0]).max() < 1e-3
    untouched = dvqp.plan(scene, "daqp")
    final = dvqp.KinematicState.compute(scene.robot, untouched.q[-1], scene.pipe_radius)
    assert abs(math.degrees(math.acos(task.cos_tilt(final)[0])) - 30.0) > 10.0


def test_a_user_limit_stops_the_probe_at_its_floor_and_relaxes_the_task() -> None:
    pytest.importorskip("daqp")
    floor = load("probe_floor").ProbeFloor(floor=0.05)
    scene = jog_scene("[0.0, 0.0, -0.02, 0.0]", duration=2.0)  # down 4 cm from h = 0.08 m
    limited = dvqp.plan(scene, "daqp", limits=[floor])
    free = dvqp.plan(scene, "daqp")
    assert free.tool[-1, 2] < 0.045
    assert limited.ok and limited.tool[:, 2].min() > 0.05 - 1e-4
    assert "relaxed" in set(limited.status) and limited.task_error.max() > 1e-3
    baseline = dvqp.plan(scene, "pinv", limits=[floor])  # the baseline holds no limit
    assert baseline.tool[-1, 2] < 0.045


def test_a_broken_user_limit_is_named_when_it_is_passed_to_check_run() -> None:
    floor = load("probe_floor").ProbeFloor(floor=0.07)
    scene = jog_scene("[0.0, 0.0, -0.02, 0.0]", duration=2.0)
    traj = dvqp.plan(scene, "pinv", limits=[floor])  # the baseline holds no limit
    with pytest.raises(dvqp.LimitViolationError, match=r"probe/floor distance .* < 0\.07 m"):
        dvqp.check_run(scene, traj, [floor])
    with pytest.raises(dvqp.LimitViolationError, match="one given to plan and not named here"):
        dvqp.check_run(scene, traj)
