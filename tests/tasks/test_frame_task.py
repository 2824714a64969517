"""A frame task (pink's FrameTask, for a URDF arm): its rows are the frame's position and
rotation derivatives, its velocity turns the frame toward its target, and a run at a lower
priority holds the frame where it started while the tool moves."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import dvqp
from dvqp import FrameTask, KinematicState, ParameterError
from tests.common import PIPE_RADIUS, central_difference

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "urdf-arm.toml"
DT = 0.005


@pytest.fixture(scope="module")
def scene() -> dvqp.Scene:
    return dvqp.load_scene(SCENE)


def pose(robot: dvqp.Robot, q: np.ndarray, frame: str) -> pin.SE3:
    """The frame's placement from Pinocchio's forward kinematics (the oracle)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.model.getFrameId(frame)].copy()


@pytest.mark.parametrize("frame", ["link8", "point3", "probe"])
def test_the_rows_are_the_frames_derivatives(scene: dvqp.Scene, frame: str) -> None:
    robot, rng = scene.robot, np.random.default_rng(7)
    q = scene.q0 + rng.uniform(-0.3, 0.3, robot.n)
    target = pose(robot, scene.q0, frame)
    task = FrameTask(robot, frame, position=target.translation, rotation=target.rotation, gain=2.0)
    rows = task.compute(KinematicState.compute(robot, q, PIPE_RADIUS), np.zeros(4), DT)
    position = central_difference(lambda v: pose(robot, v, frame).translation, q, 1e-7)
    turns = []
    for i in range(robot.n):
        e = np.zeros(robot.n)
        e[i] = 1e-7
        ahead, behind = pose(robot, q + e, frame), pose(robot, q - e, frame)
        turns.append(pin.log3(ahead.rotation @ behind.rotation.T) / 2e-7)
    np.testing.assert_allclose(rows.jacobian[:3], position, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(rows.jacobian[3:], np.array(turns).T, rtol=1e-6, atol=1e-8)
    now = pose(robot, q, frame)
    np.testing.assert_allclose(rows.velocity[:3], 2.0 * (target.translation - now.translation))
    np.testing.assert_allclose(
        rows.velocity[3:], 2.0 * pin.log3(target.rotation @ now.rotation.T), atol=1e-12
    )
    orientation = FrameTask(robot, frame, ("orientation",), rotation=target.rotation)
    found = orientation.compute(KinematicState.compute(robot, q, PIPE_RADIUS), np.zeros(4), DT)
    np.testing.assert_array_equal(found.jacobian, rows.jacobian[3:])


def test_an_unknown_frame_is_refused_listing_the_frames(scene: dvqp.Scene) -> None:
    with pytest.raises(ParameterError) as info:
        FrameTask(scene.robot, "elbow")
    message = str(info.value)
    assert message.startswith("frame: no frame named 'elbow' (model has: universe, base, joint1")
    assert "point3" in message and "probe" in message and "\n" not in message


def test_a_rotation_that_is_not_one_is_refused(scene: dvqp.Scene) -> None:
    with pytest.raises(ParameterError, match="rotation: must be a rotation matrix"):
        FrameTask(scene.robot, "probe", rotation=np.diag([1.0, 1.0, -1.0]))


def test_below_the_tool_a_frame_is_held_where_the_run_started(scene: dvqp.Scene) -> None:
    short = dataclasses.replace(scene, jog=(dvqp.JogSegment(0.4, [0.03, 0.02, 0.0, 0.1]),))
    held = FrameTask(scene.robot, "point3", ("position",), priority=2)
    traj = dvqp.plan(short, "daqp", tasks=[held])
    assert traj.ok and traj.levels == ("tool", "frame point3 position")
    start = pose(scene.robot, scene.q0, "point3").translation
    moved = np.array([pose(scene.robot, q, "point3").translation - start for q in traj.q])
    drift = float(np.abs(moved).max())
    assert drift < 1e-4  # m, in x, y and z
    # the tool's level is kept in every step; the frame's wherever nothing forbids it (as the
    # JOG ramps down, holding both may need more than qdd_max: there the frame gives way)
    assert traj.level_error[:, 0].max() < 1e-6
    assert traj.level_error[traj.status == "optimal", 1].max() < 1e-6
    np.testing.assert_allclose(traj.level_deviation[:, 1, 0].max(), drift, rtol=1e-9)
    assert np.abs(traj.tracking_error).max() < 5e-4  # the tool went on (JOG: no feedback)
    assert np.ptp(traj.tool[:, 0]) > 0.01
