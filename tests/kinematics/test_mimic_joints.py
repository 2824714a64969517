"""A URDF ``<mimic>`` joint follows its master (Pinocchio's mimic joints): no coordinate of its
own, its motion ``multiplier · q + offset`` in the frames and (added into the master's column)
the Jacobians, which agree with Pinocchio's and with finite differences; the master's limits
keep the mimic within its own; a mimic dvqp cannot follow is refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import RobotFileError
from tests.common import central_difference
from tests.kinematics import oracle

GRIPPER = """<?xml version="1.0"?>
<robot name="gripper">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="left"/><link name="right"/>
  <link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0.4 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2.0"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="1" velocity="1.0"/></joint>
  <joint name="finger" type="prismatic"><parent link="l2"/><child link="left"/>
    <origin xyz="0.1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.05" effort="1" velocity="0.4"/></joint>
  <joint name="twin" type="revolute"><parent link="l2"/><child link="right"/>
    <origin xyz="0.1 0 0" rpy="0.3 0 0"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-0.5" upper="0.3" effort="1" velocity="0.5"/>
    <mimic joint="finger" multiplier="{multiplier}" offset="{offset}"/></joint>
  <joint name="tipj" type="fixed"><parent link="right"/><child link="tip"/>
    <origin xyz="0.05 0.02 0" rpy="-1.5707963 0 0"/></joint>
</robot>
"""
"""Two joints and a finger; a revolute joint on another axis follows the prismatic finger."""


def gripper(tmp_path: Path, multiplier: str = "-4", offset: str = "0.1") -> Robot:
    path = tmp_path / "gripper.urdf"
    path.write_text(GRIPPER.format(multiplier=multiplier, offset=offset), encoding="utf-8")
    return Robot.from_urdf(path, points=["l1", "l2", "left"], tool="tip")


def test_a_mimic_joint_adds_no_coordinate_and_moves_with_its_master(tmp_path: Path) -> None:
    robot = gripper(tmp_path)
    assert robot.n == 3 and robot.joint_names == ("j1", "j2", "finger")
    rng = np.random.default_rng(7)
    for q in rng.uniform([-2, -1, 0.0], [2, 1, 0.05], size=(12, 3)):
        state = KinematicState.compute(robot, q, 0.3)
        origins, axes, jac = oracle.pinocchio_frames(robot, q)  # Pinocchio's mimic joints
        np.testing.assert_allclose(state.origins, origins, atol=1e-12)
        np.testing.assert_allclose(state.axes, axes, atol=1e-12)
        np.testing.assert_allclose(state.frame_jacobians, jac, atol=1e-12)
        tip = central_difference(lambda v: KinematicState.compute(robot, v, 0.3).origins[-1], q)
        np.testing.assert_allclose(state.frame_jacobians[-1, :3], tip, atol=1e-8)
        assert np.any(np.abs(tip[:, 2]) > 0.01)  # the finger's column moves the twin's tip


def test_the_twin_is_turned_by_multiplier_times_q_plus_offset(tmp_path: Path) -> None:
    """The tip at finger q equals the tip of the same file with the mimic as a joint of its own
    (its own column) set to ``-4 q + 0.1``."""
    robot = gripper(tmp_path)
    free = tmp_path / "free.urdf"
    text = GRIPPER.format(multiplier="-4", offset="0.1")
    free.write_text(text.replace('<mimic joint="finger" multiplier="-4" offset="0.1"/>', ""))
    unmimicked = Robot.from_urdf(free, points=["l1", "l2", "left"], tool="tip")
    assert unmimicked.n == 4
    for finger in (0.0, 0.02, 0.05):
        q = np.array([0.3, -0.4, finger])
        mine = KinematicState.compute(robot, q, 0.3).origins[-1]
        theirs = KinematicState.compute(unmimicked, [*q, -4 * finger + 0.1], 0.3).origins[-1]
        np.testing.assert_allclose(mine, theirs, atol=1e-14)


def test_the_masters_limits_keep_the_mimic_within_its_own(tmp_path: Path) -> None:
    """finger in [0, 0.05] m, twin = −4 q + 0.1 in [−0.5, 0.3] rad: q in [−0.05, 0.15], so
    [0, 0.05]; with 10 q − 0.2 instead: q in [−0.03, 0.05], so [0, 0.05] again, and its speed
    at most 0.5 / 10 = 0.05 m/s (its own 0.4)."""
    robot = gripper(tmp_path)
    assert (robot.q_min[2], robot.q_max[2], robot.qd_max[2]) == pytest.approx((0, 0.05, 0.125))
    robot = gripper(tmp_path, "10", "-0.45")  # q in [-0.005, 0.075]: the finger's own
    assert (robot.q_min[2], robot.q_max[2], robot.qd_max[2]) == pytest.approx((0.0, 0.05, 0.05))
    robot = gripper(tmp_path, "10", "-0.2")  # q in [-0.03, 0.05]
    assert (robot.q_min[2], robot.q_max[2]) == pytest.approx((0.0, 0.05))
    robot = gripper(tmp_path, "2", "0.0")  # q in [-0.25, 0.15]
    assert (robot.q_min[2], robot.q_max[2]) == pytest.approx((0.0, 0.05))
    robot = gripper(tmp_path, "20", "-0.9")  # q in [0.02, 0.06]: narrowed below
    assert (robot.q_min[2], robot.q_max[2]) == pytest.approx((0.02, 0.05))


@pytest.mark.parametrize(
    ("edit", "reason"),
    [
        (('multiplier="-4"', 'multiplier="0"'), "joint 'twin': mimic multiplier 0"),
        (('joint="finger"', 'joint="nope"'), "joint 'twin' mimics 'nope': not another joint"),
        (('joint="finger"', 'joint="twin"'), "joint 'twin' mimics 'twin': not another joint"),
        (('joint="finger"', 'joint="tipj"'), "mimics 'tipj', which is not a revolute or prism"),
        (('name="twin" type="revolute"', 'name="twin" type="continuous"'), "is continuous and"),
        (('multiplier="-4"', 'multiplier="nan"'), "mimic multiplier = 'nan': expected 1 finite"),
        (('"-4" offset="0.1"', '"200" offset="1"'), "no position of 'finger' keeps both"),
    ],
)
def test_a_mimic_dvqp_cannot_follow_is_refused_in_one_line(
    tmp_path: Path, edit: tuple[str, str], reason: str
) -> None:
    path = tmp_path / "gripper.urdf"
    text = GRIPPER.format(multiplier="-4", offset="0.1")
    assert edit[0] in text
    path.write_text(text.replace(*edit, 1), encoding="utf-8")
    with pytest.raises(RobotFileError) as caught:
        Robot.from_urdf(path, points=["l1", "l2", "left"], tool="tip")
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and reason in message and "\n" not in message
