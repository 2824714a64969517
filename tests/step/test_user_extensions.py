"""A task and a limit written by a user, each one class in a file outside the package.

The classes live in ``docs/examples/`` (the files docs/api.md shows), derive from
``dvqp.Task`` and ``dvqp.VelocityDamper`` and reach the planner through
``dvqp.plan(scene, backend, tasks=[...], limits=[...])``: in NumPy, or with a compiled kernel
of their own, which must run the same.
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
from tests.oracles.resolution import frames
from tests.oracles.resolution import tilt as tilt_of
from tests.stepping import stepper

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
SCENE = Path(__file__).resolve().parents[2] / "scenes" / "paper-two-inlets.toml"


def load(name: str) -> ModuleType:
    """An example file imported as a user's module, under its own name: numba's on-disk cache
    of its kernels refers to the module by the name it was first compiled under."""
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def tilt_task() -> type:
    """The example's ``TiltTask``: a soft :class:`dvqp.Task`."""
    task = load("tilt_task").TiltTask
    assert issubclass(task, dvqp.Task), "docs/examples/tilt_task.py: TiltTask must derive from Task"
    assert task.hard is False
    return task  # type: ignore[no-any-return]


def numpy_only(kind: type) -> type:
    """``kind`` with no kernel: a run calls its NumPy method."""
    return type(f"NumPy{kind.__name__}", (kind,), {"kernel": lambda self, plan: None})


def floors() -> dict[str, type]:
    """The example's floor limits by name: ``ProbeFloor`` (NumPy) and, if given, its compiled
    twin ``CompiledProbeFloor``."""
    module = load("probe_floor")
    kinds = {
        name: getattr(module, name)
        for name in ("ProbeFloor", "CompiledProbeFloor")
        if hasattr(module, name)
    }
    assert "ProbeFloor" in kinds
    assert all(issubclass(kind, dvqp.VelocityDamper) for kind in kinds.values())
    return kinds


FLOORS = tuple(floors())


def jog_scene(velocity: str, duration: float = 1.0) -> dvqp.Scene:
    text = SCENE.read_text(encoding="utf-8")
    start = text.index("[[motion.jog]]")
    jog = f"[[motion.jog]]\nduration = {duration}\nvelocity = {velocity}\n"
    return dvqp.scenes.loads(text[:start] + jog, "user.toml")


def test_the_tilt_row_is_the_derivative_of_the_tilt(robot: dvqp.Robot, q0: np.ndarray) -> None:
    tilt = tilt_task()
    s = stepper(robot, q0)  # one compiled step; its state is reloaded for every point

    def cos_tilt(q: np.ndarray) -> float:
        assert s.load(q)
        return float(tilt.cos_tilt(s.state)[0])  # type: ignore[attr-defined]

    for q in (q0, q0 + 0.1, q0 - np.linspace(0, 0.2, 13)):
        assert s.load(q)
        value, row = tilt.cos_tilt(s.state)  # type: ignore[attr-defined]
        assert value == pytest.approx(math.cos(tilt_of(frames(robot, q, PIPE_RADIUS))), abs=1e-12)
        np.testing.assert_allclose(row, central_difference(cos_tilt, q, 1e-7), atol=1e-7)


def test_a_user_tilt_task_turns_the_probe_while_the_tool_task_holds() -> None:
    tilt = tilt_task()
    task = tilt(tilt=math.radians(30.0), gain=2.0, weight=100.0)
    scene = jog_scene("[0.0, 0.0, 0.0, 0.0]", duration=3.0)

    def degrees(q: np.ndarray) -> float:  # the probe's tilt from Pinocchio's frames
        return math.degrees(tilt_of(frames(scene.robot, q, scene.pipe_radius)))

    traj = dvqp.plan(scene, "daqp", tasks=[task])
    assert abs(degrees(scene.q0) - 30.0) > 10.0 and abs(degrees(traj.q[-1]) - 30.0) < 1.0
    assert traj.ok and traj.task_error.max() < 1e-9  # the hard DV task is untouched
    assert np.abs(traj.tool[-1] - traj.tool[0]).max() < 1e-3
    untouched = dvqp.plan(scene, "daqp")
    assert abs(degrees(untouched.q[-1]) - 30.0) > 10.0
    if type(task).kernel is not dvqp.Task.kernel:  # its compiled rows are its NumPy rows
        plain = numpy_only(tilt)(tilt=math.radians(30.0), gain=2.0, weight=100.0)
        again = dvqp.plan(scene, "daqp", tasks=[plain])
        np.testing.assert_allclose(again.q, traj.q, rtol=0, atol=1e-9)


@pytest.mark.parametrize("kind", FLOORS)
def test_a_user_limit_stops_the_probe_at_its_floor_and_relaxes_the_task(kind: str) -> None:
    floor = floors()[kind](floor=0.05)
    scene = jog_scene("[0.0, 0.0, -0.02, 0.0]", duration=2.0)  # down 4 cm from h = 0.08 m
    limited = dvqp.plan(scene, "daqp", limits=[floor])
    free = dvqp.plan(scene, "daqp")
    assert free.tool[-1, 2] < 0.045
    assert limited.ok and limited.tool[:, 2].min() > 0.05 - 1e-4
    probe = [frames(scene.robot, q, scene.pipe_radius).tool[2] for q in limited.q[::10]]
    assert min(probe) > 0.05 - 1e-4  # the probe's true height
    assert "relaxed" in set(limited.status) and limited.task_error.max() > 1e-3
    baseline = dvqp.plan(scene, "pinv", limits=[floor])  # the baseline holds no limit
    assert baseline.tool[-1, 2] < 0.045


def test_a_compiled_user_limit_runs_as_its_numpy_twin() -> None:
    kinds = floors()
    if "CompiledProbeFloor" not in kinds:
        pytest.skip("docs/examples/probe_floor.py has no compiled limit")
    scene = jog_scene("[0.0, 0.0, -0.02, 0.0]", duration=2.0)
    plain, compiled = (
        dvqp.plan(scene, "daqp", limits=[kinds[name](floor=0.05)])
        for name in ("ProbeFloor", "CompiledProbeFloor")
    )
    np.testing.assert_allclose(compiled.q, plain.q, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(compiled.status, plain.status)


@pytest.mark.parametrize("kind", FLOORS)
def test_a_broken_user_limit_is_named_when_it_is_passed_to_check_run(kind: str) -> None:
    floor = floors()[kind](floor=0.07)
    scene = jog_scene("[0.0, 0.0, -0.02, 0.0]", duration=2.0)
    traj = dvqp.plan(scene, "pinv", limits=[floor])  # the baseline holds no limit
    with pytest.raises(dvqp.LimitViolationError, match=r"probe/floor distance .* < 0\.07 m"):
        dvqp.check_run(scene, traj, [floor])
    with pytest.raises(dvqp.LimitViolationError, match="one given to plan and not named here"):
        dvqp.check_run(scene, traj)
