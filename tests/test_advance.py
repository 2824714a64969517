"""Verified steps: integrate, check every limit exactly, split a step that breaks one."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp import KinematicState
from dvqp.limits import AccelerationLimit
from dvqp.motion.advance import advance
from dvqp.planning import scene_commands
from dvqp.resolution import make_resolver

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "paper-two-inlets.toml"


@functools.cache
def paper(dt: float) -> dvqp.Scene:
    text = SCENE.read_text(encoding="utf-8").replace("dt = 0.005", f"dt = {dt}")
    return dvqp.scenes.loads(text, f"paper-dt{dt}.toml")


def run(dt: float, backend: str = "daqp", **kw: object) -> dvqp.Trajectory:
    scene = paper(dt)
    resolver = make_resolver(backend, scene.spec())
    c = scene_commands(scene)
    return dvqp.simulate(
        scene.robot, scene.pipe_radius, resolver, scene.q0, c.velocity, scene.dt,
        obstacles=scene.obstacles, **kw,  # type: ignore[arg-type]
    )  # fmt: skip


def test_a_large_step_that_breaks_a_limit_is_split_and_then_keeps_it() -> None:
    pytest.importorskip("daqp")
    traj = run(0.5)
    assert traj.ok and traj.substeps.max() > 1
    assert traj.limits_kept.all() and traj.limit_excess.max() <= 1e-4
    split = int(np.argmax(traj.substeps))
    # the step's joint velocity is the mean over its substeps
    np.testing.assert_allclose(traj.q[split + 1], traj.q[split] + 0.5 * traj.qdot[split])


def test_without_splitting_the_step_fails_and_names_the_limit() -> None:
    pytest.importorskip("daqp")
    traj = run(0.5, max_halvings=0)
    failed = np.flatnonzero(~traj.success)
    assert failed.size > 0
    status = str(traj.status[failed[0]])
    assert status.startswith("failed: ") and " in 1 substeps" in status and "\n" not in status
    assert any(word in status for word in ("clearance", "height", "tilt", "joint position"))
    # a failed step holds the arm still, and every saved sample keeps every limit
    np.testing.assert_array_equal(traj.q[failed[0] + 1], traj.q[failed[0]])
    assert traj.limits_kept.all()


def test_the_baseline_is_measured_not_verified() -> None:
    traj = run(0.005, "pinv")
    assert traj.ok and (traj.substeps == 1).all()
    assert not traj.limits_kept.all() and traj.limit_excess.max() > 0.01


def test_advance_returns_the_state_it_reached() -> None:
    pytest.importorskip("daqp")
    scene = paper(0.005)
    resolver = make_resolver("daqp", scene.spec())
    start = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius)
    moved = advance(
        scene.robot, scene.pipe_radius, resolver, start, np.array([0.05, 0, 0, 0]), 0.005
    )
    assert moved.substeps == 1 and moved.step.success
    np.testing.assert_allclose(moved.state.q, start.q + 0.005 * moved.step.qdot)
    # from rest, the joints may only reach q̈_max·dt: the task gives way, and says by how much
    assert moved.step.status == "relaxed" and 0 < moved.step.task_error < 0.05
    reached = start.tool_jacobian @ moved.step.qdot
    assert moved.state.tool[0] - start.tool[0] == pytest.approx(0.005 * reached[0], abs=1e-6)
    acceleration = next(x for x in resolver.spec.limits if isinstance(x, AccelerationLimit))
    np.testing.assert_array_equal(acceleration.previous, moved.step.qdot)  # it was told
