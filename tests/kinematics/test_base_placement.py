"""A robot placed in the pipe's frame (``Robot.placed``, ``from_urdf(base=...)``, a scene's
``[robot.base]``) is the robot of the same URDF with a fixed joint from the pipe's frame to its
base link: the same frames and Jacobians to 1e-12, checked against that edited file read by
Pinocchio, not against dvqp's own placement."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.scenes.robot_section import base_transform
from tests.kinematics import oracle

ROOT = Path(__file__).resolve().parents[2]
PANDA = ROOT / "scenes" / "robots" / "panda" / "panda.urdf"
POINTS = ["panda_link0", "panda_link2", "panda_link4", "panda_link5", "panda_link7"]
TOOL = "panda_hand_tcp"
XYZ, RPY = [0.12, 0.31, -0.4], [-1.2, 0.7, 2.5]


def mounted(tmp_path: Path) -> Robot:
    """The Panda with a root link ``pipe`` and a fixed joint placing ``panda_link0`` in it."""
    text = PANDA.read_text(encoding="utf-8")
    mount = (
        '<link name="pipe"/><joint name="mount" type="fixed"><parent link="pipe"/>'
        f'<child link="panda_link0"/><origin xyz="{" ".join(map(repr, XYZ))}" '
        f'rpy="{" ".join(map(repr, RPY))}"/></joint>'
    )
    path = tmp_path / "mounted.urdf"
    path.write_text(text.replace("</robot>", mount + "</robot>"), encoding="utf-8")
    return Robot.from_urdf(path, POINTS, TOOL)


def test_a_placed_robot_is_the_robot_mounted_by_a_fixed_joint(tmp_path: Path) -> None:
    placed = Robot.from_urdf(PANDA, POINTS, TOOL, base=base_transform(XYZ, RPY))
    reference = mounted(tmp_path)
    assert placed.n == reference.n == 8
    rng = np.random.default_rng(11)
    for q in rng.uniform(placed.q_min, placed.q_max, size=(20, 8)):
        state = KinematicState.compute(placed, q, 0.3)
        origins, axes, jac = oracle.pinocchio_frames(reference, q)
        np.testing.assert_allclose(state.origins, origins, atol=1e-12)
        np.testing.assert_allclose(state.axes, axes, atol=1e-12)
        np.testing.assert_allclose(state.frame_jacobians, jac, atol=1e-12)
    # the base link itself (attached to the world, no joint moves it) is placed too
    np.testing.assert_allclose(state.origins[0], XYZ, atol=1e-15)


def test_placing_keeps_everything_else_and_refuses_a_transform_that_is_not_rigid() -> None:
    robot = Robot.from_urdf(PANDA, POINTS, TOOL)
    placed = robot.placed(base_transform(XYZ, RPY))
    assert placed.part_names == robot.part_names and placed.joint_names == robot.joint_names
    for a, b in ((placed.q_min, robot.q_min), (placed.q_max, robot.q_max)):
        np.testing.assert_array_equal(a, b)
    base = base_transform(XYZ, RPY)
    for q in (np.zeros(8), np.linspace(-0.5, 0.02, 8)):  # every frame moved by the base
        origins, axes, _ = oracle.pinocchio_frames(placed, q)
        before, axes_before, _ = oracle.pinocchio_frames(robot, q)
        np.testing.assert_allclose(origins, before @ base[:3, :3].T + base[:3, 3], atol=1e-14)
        np.testing.assert_allclose(axes, axes_before @ base[:3, :3].T, atol=1e-14)
    sheared = base_transform(XYZ, RPY)
    sheared[0, 1] += 0.1
    with pytest.raises(ParameterError, match=r"^base: "):
        robot.placed(sheared)
