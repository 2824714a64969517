"""dvqp's compiled kinematics (its only kinematics) agree with Pinocchio to 1e-12: frames, frame
Jacobians (LOCAL_WORLD_ALIGNED) and the developed view, for the paper's arm, the URDF arm,
prismatic, unaligned and branching models; other joint types are refused up front."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError, SingularConfigurationError
from dvqp.kinematics import developed_view as dv
from dvqp.kinematics.model import kinematics
from dvqp.workspace import StateBuffers, as_struct
from tests.common import central_difference, random_configurations
from tests.kinematics import oracle
from tests.runs import scene


def assert_matches_pinocchio(robot: Robot, q: np.ndarray, radius: float) -> KinematicState:
    """Every field of the compiled state equals the Pinocchio/NumPy reference to 1e-12."""
    state = KinematicState.compute(robot, q, radius)
    for field, want in oracle.reference(robot, q, radius).items():
        np.testing.assert_allclose(getattr(state, field), want, rtol=0, atol=1e-12, err_msg=field)
    return state


@pytest.mark.parametrize("name", ["paper-two-inlets", "urdf-arm"])
def test_frames_jacobians_and_developed_view_match_pinocchio(name: str) -> None:
    s = scene(name)
    for q in random_configurations(40, seed=3, spread=0.8):
        assert_matches_pinocchio(s.robot, q, s.pipe_radius)


def test_the_urdf_arm_has_continuous_joints_and_matches_the_arm_built_in_code() -> None:
    urdf, paper = scene("urdf-arm").robot, scene("paper-two-inlets").robot
    assert urdf.q_min[0] == -np.inf and urdf.q_max[0] == np.inf  # the carriage is continuous
    for q in random_configurations(10, seed=4, spread=3.0):
        mine = KinematicState.compute(urdf, q, 0.254)
        theirs = KinematicState.compute(paper, q, 0.254)
        for field in oracle.FIELDS:
            np.testing.assert_allclose(
                getattr(mine, field), getattr(theirs, field), rtol=0, atol=1e-12, err_msg=field
            )


def placement(rpy: tuple[float, float, float], xyz: tuple[float, float, float]) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(np.array(rpy)), np.array(xyz))


def mixed_joint_robot() -> Robot:
    """A chain RX, PY, revolute about (0.3, 0.5, 0.8), prismatic along (−0.2, 0.7, 0.4), tilted
    placements, with a side branch (a joint that moves no guarded frame) in the middle of it."""
    model = pin.Model()
    parent = 0
    joints = [
        pin.JointModelRX(),
        pin.JointModelPY(),
        pin.JointModelRevoluteUnaligned(0.3, 0.5, 0.8),
        pin.JointModelPrismaticUnaligned(-0.2, 0.7, 0.4),
    ]
    rpys = [(0.0, 0.0, 0.0), (0.3, -0.2, 1.1), (-0.7, 0.4, 0.2), (0.5, 0.1, -0.6)]
    offsets = [(0.3, 0.0, 0.0), (0.05, 0.1, -0.02), (0.0, -0.04, 0.12), (0.07, 0.02, 0.03)]
    for i, joint in enumerate(joints):
        parent = model.addJoint(parent, joint, placement(rpys[i], offsets[i]), f"j{i}")
        at = placement(rpys[-1 - i], offsets[-1 - i])
        model.addFrame(pin.Frame(f"f{i}", parent, 0, at, pin.FrameType.OP_FRAME))
        if i == 1:  # a side branch off joint j1: its q sits between the chain's
            side = model.addJoint(
                parent, pin.JointModelRZ(), placement((0.1, 0, 0), (0, 0.1, 0)), "side"
            )
            model.addFrame(pin.Frame("s", side, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return Robot(model, ["f0", "f1", "f2"], "f3", q_min=-3.0, q_max=3.0)


def test_prismatic_unaligned_and_branching_joints_match_pinocchio() -> None:
    robot = mixed_joint_robot()
    assert robot.n == 5
    rng = np.random.default_rng(2)
    for _ in range(20):
        state = assert_matches_pinocchio(robot, rng.uniform(-1.0, 1.0, robot.n), 0.05)
        side = robot.model.joints[robot.model.getJointId("side")].idx_q
        assert not state.frame_jacobians[:, :, side].any()  # the branch moves no guarded frame


def test_the_developed_view_rows_of_prismatic_joints_equal_finite_differences() -> None:
    robot, r = mixed_joint_robot(), 0.05

    def wrap(d: np.ndarray) -> np.ndarray:  # l and α differences across the seam
        d = d.copy()
        d[..., 0] = dv.wrap(d[..., 0], r)
        if d.shape[-1] == 4:
            d[..., 3] = dv.wrap_angle(d[..., 3])
        return d

    for q in np.random.default_rng(5).uniform(-1.0, 1.0, (5, robot.n)):
        state = KinematicState.compute(robot, q, r)
        fd = central_difference(lambda v: KinematicState.compute(robot, v, r).tool, q, 1e-7, wrap)
        np.testing.assert_allclose(state.tool_jacobian, fd, rtol=1e-6, atol=1e-7)
        fd = central_difference(
            lambda v: KinematicState.compute(robot, v, r).guarded, q, 1e-7, wrap
        )
        np.testing.assert_allclose(state.guarded_jacobians, fd, rtol=1e-6, atol=1e-7)


def frames_on_the_axis_robot() -> Robot:
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j")
    offsets = {"a": [0.2, 0.0, 0.0], "b": [0.0, 0.0, 0.1], "c": [0.0, 0.3, 0.0]}
    for name, offset in offsets.items():
        at = pin.SE3(np.eye(3), np.array(offset))
        model.addFrame(pin.Frame(name, joint, 0, at, pin.FrameType.OP_FRAME))
    return Robot(model, ["a", "b"], "c", q_min=-1.0, q_max=1.0)


def test_a_frame_on_the_pipe_axis_is_reported_by_its_index_and_named() -> None:
    robot = frames_on_the_axis_robot()
    buffers = StateBuffers.allocate(robot.n, robot.n_points)
    buffers.q[:] = 0.4
    assert kinematics(as_struct(robot.model_arrays()), 0.05, as_struct(buffers)) == 1
    with pytest.raises(SingularConfigurationError, match=r"frame 'b' lies on the pipe axis"):
        KinematicState.compute(robot, [0.4], 0.05)


def _model_with(joint: pin.JointModel) -> pin.Model:
    model = pin.Model()
    j = model.addJoint(0, joint, pin.SE3.Identity(), "odd")
    for name in ("a", "b", "c"):
        at = placement((0.1, 0.2, 0.3), (0.2, 0.1, 0.0))
        model.addFrame(pin.Frame(name, j, 0, at, pin.FrameType.OP_FRAME))
    return model


@pytest.mark.parametrize(
    "joint",
    [
        pin.JointModelTranslation(),
        pin.JointModelSphericalZYX(),
        pin.JointModelHZ(),
        pin.JointModelHelicalUnaligned(0.0, 0.6, 0.8, 0.1),
        pin.JointModelUniversal(1.0, 0.0, 0.0, 0.0, 1.0, 0.0),
    ],
    ids=lambda j: j.shortname(),
)
def test_a_joint_that_is_not_revolute_or_prismatic_is_refused_when_the_robot_is_built(
    joint: pin.JointModel,
) -> None:
    kind = joint.shortname().removeprefix("JointModel")
    with pytest.raises(ParameterError, match=rf"^model: joint 'odd' is a {kind} joint: only"):
        Robot(_model_with(joint), ["a", "b"], "c")


@pytest.mark.parametrize(
    "joint",
    [
        pin.JointModelSpherical(),
        pin.JointModelPlanar(),
        pin.JointModelFreeFlyer(),
        pin.JointModelRUBZ(),
    ],
    ids=lambda j: j.shortname(),
)
def test_a_joint_whose_configuration_is_not_its_velocity_is_refused(
    joint: pin.JointModel,
) -> None:
    with pytest.raises(ParameterError, match=r"^model: only joints with nq == nv"):
        Robot(_model_with(joint), ["a", "b"], "c")
