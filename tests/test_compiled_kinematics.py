"""The compiled kinematics agree with Pinocchio (the reference path) to 1e-12."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from dvqp import KinematicState, Robot
from dvqp.compiled import StepPlan
from dvqp.compiled.kinematics import CompiledModel
from tests.common import random_configurations
from tests.runs import scene

FIELDS = ("q", "origins", "axes", "frame_jacobians", "guarded", "guarded_jacobians", "tool",
          "tool_jacobian")  # fmt: skip


def compiled_state(robot: Robot, q: np.ndarray, radius: float) -> tuple[StepPlan, int]:
    plan = StepPlan(robot.n, robot.n_points, radius)
    model = CompiledModel.of(robot)
    assert model is not None
    kernel = model.kernel(plan)
    plan.state.q[:] = q
    return plan, kernel.function(*kernel.args)


@pytest.mark.parametrize("name", ["paper-two-inlets", "urdf-arm"])
def test_frames_jacobians_and_developed_view_match_pinocchio(name: str) -> None:
    s = scene(name)
    for q in random_configurations(40, seed=3, spread=0.8):
        plan, status = compiled_state(s.robot, q, s.pipe_radius)
        assert status == -1
        ref = KinematicState.compute(s.robot, q, s.pipe_radius)
        for field in FIELDS:
            np.testing.assert_allclose(getattr(plan.state, field), getattr(ref, field),
                                       rtol=0, atol=1e-12, err_msg=field)  # fmt: skip


def test_a_frame_on_the_pipe_axis_is_reported_by_its_index() -> None:
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    offsets = {"a": [0.2, 0.0, 0.0], "b": [0.0, 0.0, 0.1], "c": [0.0, 0.3, 0.0]}
    for name, offset in offsets.items():
        placement = pin.SE3(np.eye(3), np.array(offset))
        model.addFrame(pin.Frame(name, joint, 0, placement, pin.FrameType.OP_FRAME))
    robot = Robot(model, ["a", "b"], "c", q_min=-1.0, q_max=1.0)
    _, status = compiled_state(robot, np.array([0.4]), 0.05)
    assert status == 1  # frame "b" sits on the axis (rho = 0)


def placement(rpy: tuple[float, float, float], xyz: tuple[float, float, float]) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)), np.array(xyz))


def _prismatic_and_revolute_model() -> Robot:
    model = pin.Model()
    parent = 0
    joints = [
        pin.JointModelRX(),
        pin.JointModelPY(),
        pin.JointModelRevoluteUnaligned(0.3, 0.5, 0.8),
    ]
    rpys = [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1), (-0.7, 0.4, 0.2)]
    offsets = [(0.3, 0.0, 0.0), (0.05, 0.1, -0.02), (0.0, -0.04, 0.12)]
    for i, joint in enumerate(joints):
        parent = model.addJoint(parent, joint, placement(rpys[i], offsets[i]), f"j{i}")
        at = placement(rpys[-1 - i], offsets[-1 - i])
        model.addFrame(pin.Frame(f"f{i}", parent, 0, at, pin.FrameType.OP_FRAME))
    return Robot(model, ["f0", "f1"], "f2", q_min=-3.0, q_max=3.0)


def test_prismatic_and_unaligned_joints_match_pinocchio() -> None:
    robot = _prismatic_and_revolute_model()
    rng = np.random.default_rng(2)
    for _ in range(20):
        q = rng.uniform(-1.0, 1.0, robot.n)
        plan, status = compiled_state(robot, q, 0.05)
        ref = KinematicState.compute(robot, q, 0.05)
        assert status == -1
        for field in FIELDS:
            np.testing.assert_allclose(getattr(plan.state, field), getattr(ref, field),
                                       rtol=0, atol=1e-12, err_msg=field)  # fmt: skip


def test_a_joint_that_is_not_a_fixed_axis_is_not_compiled() -> None:
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelTranslation(), pin.SE3.Identity(), "free")
    for name in ("a", "b", "c"):
        at = placement((0.1, 0.2, 0.3), (0.2, 0.1, 0.0))
        model.addFrame(pin.Frame(name, j, 0, at, pin.FrameType.OP_FRAME))
    robot = Robot(model, ["a", "b"], "c", q_min=-1.0, q_max=1.0)
    assert CompiledModel.of(robot) is None
