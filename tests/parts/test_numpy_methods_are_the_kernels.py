"""Every built-in part's NumPy method returns exactly the rows its kernel writes in the step.

A task's ``compute``, a term's ``evaluate`` and a limit's ``compute`` / ``distances`` call the
part's own compiled kernel on the state; the step writes the same kernel's rows into its
buffers. Both are read here at states of the paper scene near its obstacles, with every row
measured exactly (no broad phase), and compared bit for bit.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.shapes import Circle
from dvqp.limits import VelocityDamper
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "scenes" / "paper-two-inlets.toml"
DT = 0.01
COMMAND = np.array([0.01, -0.02, 0.005, 0.1])


@pytest.fixture(scope="module")
def scene() -> dvqp.Scene:
    return dvqp.load_scene(SCENE)


@pytest.fixture(scope="module")
def states(scene: dvqp.Scene) -> list[np.ndarray]:
    """The start and the sample of the scene's run closest to an obstacle."""
    traj = dvqp.plan(scene, "pinv")
    closest = int(np.argmin(traj.min_clearance))
    return [np.array(scene.q0), traj.q[closest], traj.q[len(traj.q) // 2]]


def _stepper(scene: dvqp.Scene, q: np.ndarray) -> dvqp.Stepper:
    resolver = dvqp.make_resolver("daqp", scene.spec())
    stepper = dvqp.Stepper(scene.robot, scene.pipe_radius, resolver, q, DT, scene.obstacles)
    stepper.arrays.shapes.far[:] = np.inf  # every row exact
    stepper.arrays.shapes.refine[:] = np.inf
    assert stepper.load(q)
    assert stepper.prepare(COMMAND, DT) == -1
    return stepper


def test_each_damper_distances_are_its_kernel_rows(scene: dvqp.Scene, states: list) -> None:
    seen = set()
    for q in states:
        stepper = _stepper(scene, q)
        state = dvqp.KinematicState.compute(scene.robot, q, scene.pipe_radius)
        d = stepper.arrays.dampers
        for block in stepper.layout.blocks:
            if not block.damper:
                continue
            limit = block.limit
            assert isinstance(limit, VelocityDamper)
            rows = slice(
                block.start - stepper.layout.damper_values,
                block.stop - stepper.layout.damper_values,
            )
            found = limit.distances(state)
            np.testing.assert_array_equal(found.value, d.distance[rows], err_msg=limit.name)
            assert found.usable is not None
            np.testing.assert_array_equal(found.usable, d.usable[rows], err_msg=limit.name)
            usable = found.usable
            np.testing.assert_array_equal(
                found.gradient[usable], d.gradient[rows][usable], err_msg=limit.name
            )
            assert len(found.describe()) == found.value.shape[0] == block.stop - block.start
            assert np.all(np.asarray(found.safe) == limit.safe)
            seen.add(type(limit).__name__)
    assert seen == {"ObstacleDamper", "SurfaceHeight", "ProbeHeight", "TiltLimit", "SelfCollision"}


def test_the_terms_evaluate_to_the_steps_objective(scene: dvqp.Scene, states: list) -> None:
    for q in states:
        state = dvqp.KinematicState.compute(scene.robot, q, scene.pipe_radius)
        # obstacles round body points 2 and 4 and link 3, so that the repulsion acts
        inside = [
            Circle(state.points[1, :2].copy(), 0.03, weight=2.0),
            Circle(0.5 * (state.points[2, :2] + state.points[3, :2]), 0.02),
            *scene.obstacles,
        ]
        obstacles = ObstacleSet(inside)
        terms = (
            OrbitalLevel(scene.orbital_level, k_height=np.linspace(1.0, 2.0, scene.robot.n_points)),
            ObstaclePoints(obstacles, k_obstacle=0.7),
            ObstacleLinks(obstacles, k_obstacle=np.linspace(0.5, 1.5, scene.robot.n_points)),
        )
        changed = dataclasses.replace(scene, objective=dvqp.Objective(terms, 0.8))
        stepper = _stepper(changed, q)
        found = [term.evaluate(state) for term in terms]
        assert all(t.value != 0.0 for t in found)
        value = sum(t.value for t in found)
        gradient = np.sum([t.gradient for t in found], axis=0)
        np.testing.assert_allclose(value, stepper.objective.value, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(gradient, stepper.objective.gradient, rtol=1e-12, atol=1e-15)


def test_the_tool_task_computes_the_steps_task_rows(scene: dvqp.Scene, states: list) -> None:
    for q in states:
        stepper = _stepper(scene, q)
        state = dvqp.KinematicState.compute(scene.robot, q, scene.pipe_radius)
        rows = dvqp.ToolTask().compute(state, COMMAND, DT)
        np.testing.assert_array_equal(rows.jacobian, stepper.arrays.qp.A[:4])
        np.testing.assert_array_equal(rows.velocity, stepper.arrays.qp.b[:4])
        assert rows.describe is not None and len(rows.describe()) == 4


def test_the_joint_limits_compute_the_steps_box(scene: dvqp.Scene, states: list) -> None:
    boxes = [x for x in scene.limits if not isinstance(x, VelocityDamper)]
    assert {type(x).__name__ for x in boxes} == {
        "JointPositionLimit",
        "JointVelocityLimit",
        "AccelerationLimit",
    }
    for q in states:
        for limit in boxes:
            limit.reset()
        stepper = _stepper(scene, q)
        state = dvqp.KinematicState.compute(scene.robot, q, scene.pipe_radius)
        lb, ub = np.full(scene.robot.n, -np.inf), np.full(scene.robot.n, np.inf)
        for limit in boxes:
            box = limit.compute(state, DT)
            assert isinstance(box, dvqp.Bounds)
            lb, ub = np.maximum(lb, box.lb), np.minimum(ub, box.ub)
        np.testing.assert_array_equal(lb, stepper.arrays.qp.lb)
        np.testing.assert_array_equal(ub, stepper.arrays.qp.ub)
