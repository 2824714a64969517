"""A built-in part is a part: a plain subclass of each keeps its compiled path.

Every task, objective term and limit of the paper scene, and every obstacle shape, replaced by
a trivial subclass of its class (same state), plans the very same trajectory as the scene
itself, and at the same step cost (it is the same compiled step: nothing recognises a part by
its exact class). A subclass that replaces the built-in's NumPy method joins as a part of your
own instead.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp.limits import SurfaceHeight
from dvqp.limits.damper import Distances
from tests.step.subclassing import subclassed, subclassed_tool_task, swapped

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "paper-two-inlets.toml"


def test_every_builtin_of_the_paper_scene_subclassed_plans_the_same_trajectory() -> None:
    scene = dvqp.load_scene(SCENE)
    changed, names = swapped(scene)
    assert set(names) >= {
        "MyJointPositionLimit",
        "MyJointVelocityLimit",
        "MyAccelerationLimit",
        "MyObstacleDamper",
        "MySurfaceHeight",
        "MyProbeHeight",
        "MyTiltLimit",
        "MySelfCollision",
        "MyOrbitalLevel",
        "MyObstaclePoints",
        "MyObstacleLinks",
    }
    reference = dvqp.plan(scene, "daqp")
    with subclassed_tool_task():
        assert type(changed.spec().tasks[0]).__name__ == "MyToolTask"
        found = dvqp.plan(changed, "daqp")
    assert reference.q.shape == found.q.shape
    np.testing.assert_allclose(found.q, reference.q, rtol=0.0, atol=1e-9)
    assert dvqp.check_run(changed, found) is None
    # the same compiled step, not the hooks of parts of your own: the same cost a step
    # (benchmarks/step_benchmark.py prints the two steps' medians side by side)
    resolver = dvqp.make_resolver("daqp", changed.spec())
    stepper = dvqp.Stepper(changed.robot, changed.pipe_radius, resolver, changed.q0, changed.dt)
    assert not stepper.layout.hooks.active


def test_a_subclass_that_replaces_the_numpy_method_joins_as_a_part_of_its_own() -> None:
    calls = []

    class CountedHeight(SurfaceHeight):
        def distances(self, state: dvqp.KinematicState) -> Distances:
            calls.append(1)
            return Distances(state.points[:, 2].copy(), state.point_jacobians[:, 2].copy(), 0.0)

    scene = dvqp.load_scene(SCENE)
    limits = tuple(CountedHeight() if type(x) is SurfaceHeight else x for x in scene.limits)
    changed = dataclasses.replace(scene, limits=limits)
    dvqp.plan(changed, "daqp")
    assert calls, "the subclass's own distances were never called"
    resolver = dvqp.make_resolver("daqp", changed.spec())
    assert dvqp.Stepper(
        changed.robot, changed.pipe_radius, resolver, changed.q0, 0.01
    ).layout.hooks.active


@pytest.mark.parametrize("shape", ["Circle", "Inlet", "Band", "Polygon"])
def test_a_subclassed_shape_keeps_its_compiled_measurement(shape: str) -> None:
    from dvqp.geometry import shapes as kinds

    cls = getattr(kinds, shape)
    base = {
        "Circle": lambda: kinds.Circle(np.array([0.0, 0.1]), 0.05),
        "Inlet": lambda: kinds.Inlet(np.array([0.0, 0.1]), 0.05, 0.2),
        "Band": lambda: kinds.Band(0.1, 0.2),
        "Polygon": lambda: kinds.Polygon(np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]])),
    }[shape]()
    mine = subclassed(base)
    assert isinstance(mine, cls)
    ours, theirs = mine.compiled(), base.compiled()
    assert ours is not None and theirs is not None
    assert ours.kernels is theirs.kernels  # its kind's very kernels
    for name in ("data", "box", "samples"):
        assert np.array_equal(getattr(ours, name), getattr(theirs, name)), name

    class Measured(cls):  # type: ignore[misc, valid-type]
        def point_distance(self, lz, period):  # type: ignore[no-untyped-def]
            return np.zeros(lz.shape[0]), np.zeros((lz.shape[0], 2))

    changed = object.__new__(Measured)
    changed.__dict__.update(base.__dict__)
    assert changed.compiled() is None  # its own NumPy distances: measured as a shape of yours
