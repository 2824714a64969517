from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import DvqpError, ParameterError, RobotFileError, ShapeError
from tests.common import LINK_LENGTHS

URDF = """<?xml version="1.0"?>
<robot name="arm3">
  <link name="base"/>
  <link name="l1"/><link name="l2"/><link name="l3"/><link name="probe"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="2.0"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1.0"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 0 0.1"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="0.5"/></joint>
  <joint name="tool" type="fixed"><parent link="l3"/><child link="probe"/>
    <origin xyz="0 0.1 0" rpy="-1.5707963 0 0"/></joint>
</robot>
"""


def test_ndt13_has_thirteen_joints_five_points_and_default_limits(robot: Robot) -> None:
    assert robot.n == 13 and robot.n_points == 5
    assert robot.q_min[0] == -np.inf and robot.q_max[1] == pytest.approx(np.pi)
    assert np.all(robot.qd_max == 1.5)


def test_urdf_robot_reads_limits_and_named_frames(tmp_path: Path) -> None:
    path = tmp_path / "arm3.urdf"
    path.write_text(URDF)
    robot = Robot.from_urdf(path, points=["l2", "l3"], tool="probe")
    assert robot.n == 3
    np.testing.assert_allclose(robot.q_max, [3, 1, 2])
    np.testing.assert_allclose(robot.qd_max, [2.0, 1.0, 0.5])
    state = KinematicState.compute(robot, np.zeros(3), 0.3)
    assert state.tool_jacobian.shape == (4, 3) and state.points.shape == (2, 3)
    np.testing.assert_allclose(state.origins[-1], [0.4, 0.1, 0.1], atol=1e-12)


def test_urdf_errors_name_the_file_and_the_missing_frame(tmp_path: Path) -> None:
    with pytest.raises(DvqpError, match=r"missing\.urdf"):
        Robot.from_urdf(tmp_path / "missing.urdf", points=["a", "b"], tool="c")
    path = tmp_path / "arm3.urdf"
    path.write_text(URDF)
    with pytest.raises(ParameterError, match="'nope'"):
        Robot.from_urdf(path, points=["l1", "nope"], tool="probe")


def test_limits_are_validated() -> None:
    with pytest.raises(ShapeError, match="q_min"):
        Robot.ndt13(LINK_LENGTHS, q_min=np.zeros(12))
    with pytest.raises(ParameterError, match="q_min"):
        Robot.ndt13(LINK_LENGTHS, q_min=1.0, q_max=0.0)
    with pytest.raises(ParameterError, match="qd_max"):
        Robot.ndt13(LINK_LENGTHS, qd_max=0.0)


SCENES = Path(__file__).resolve().parents[2] / "scenes"


def frames_at(robot: Robot, q: np.ndarray) -> list[np.ndarray]:
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return [data.oMf[i].homogeneous.copy() for i in robot.frame_ids]


def test_the_bundled_urdf_is_the_ndt13_arm(robot: Robot) -> None:
    points = [f"point{k}" for k in range(1, 6)]
    urdf = Robot.from_urdf(SCENES / "ndt13.urdf", points, "probe", rail="rail")
    assert urdf.n == 13 and urdf.name == "ndt13-urdf"
    np.testing.assert_array_equal(urdf.q_min, robot.q_min)  # joint 1 continuous: unlimited
    np.testing.assert_allclose(urdf.q_max, robot.q_max, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(urdf.qd_max, robot.qd_max)
    for q in np.random.default_rng(1).uniform(-4.0, 4.0, size=(20, 13)):
        for mine, theirs in zip(frames_at(urdf, q), frames_at(robot, q), strict=True):
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12)


def test_continuous_joints_on_any_axis_become_unlimited_revolute_joints(tmp_path: Path) -> None:
    text = (
        URDF.replace('name="j1" type="revolute"', 'name="j1" type="continuous"')
        .replace('name="j3" type="revolute"', 'name="j3" type="continuous"')
        .replace(
            '<origin xyz="0 0 0.1"/><axis xyz="1 0 0"/>',
            '<origin xyz="0 0 0.1"/><axis xyz="0.6 0.8 0"/>',
        )
    )
    (tmp_path / "c.urdf").write_text(text)
    (tmp_path / "r.urdf").write_text(URDF.replace('<axis xyz="1 0 0"/>', '<axis xyz="0.6 0.8 0"/>'))
    cont = Robot.from_urdf(tmp_path / "c.urdf", points=["l2", "l3"], tool="probe")
    rev = Robot.from_urdf(tmp_path / "r.urdf", points=["l2", "l3"], tool="probe")
    assert cont.n == 3 and cont.model.nq == cont.model.nv == 3
    np.testing.assert_array_equal(cont.q_min, [-np.inf, -1.0, -np.inf])
    np.testing.assert_array_equal(cont.q_max, [np.inf, 1.0, np.inf])
    np.testing.assert_allclose(cont.qd_max, [2.0, 1.0, 0.5])
    assert [f.name for f in cont.model.frames] == [f.name for f in rev.model.frames]
    raw = pin.buildModelFromUrdf(str(tmp_path / "c.urdf"))  # continuous: q = (cos, sin)
    raw_data = raw.createData()
    for q in ([0.0, 0.0, 0.0], [5.0, 0.5, -4.0], [-7.0, -0.9, 2.5]):
        for a, b in zip(frames_at(cont, np.array(q)), frames_at(rev, np.array(q)), strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
        pin.framesForwardKinematics(
            raw, raw_data, np.array([np.cos(q[0]), np.sin(q[0]), q[1], np.cos(q[2]), np.sin(q[2])])
        )
        mine = KinematicState.compute(cont, q, 0.3)
        theirs = KinematicState.compute(rev, q, 0.3)
        for i, name in enumerate(cont.frame_names):
            frame = raw_data.oMf[raw.getFrameId(name)]
            np.testing.assert_allclose(mine.origins[i], frame.translation, rtol=0, atol=1e-12)
            np.testing.assert_allclose(mine.axes[i], frame.rotation[:, 2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(mine.frame_jacobians, theirs.frame_jacobians, rtol=0, atol=1e-12)


def test_other_joints_are_refused_and_the_parser_stays_quiet(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "planar.urdf"
    path.write_text(URDF.replace('name="j2" type="revolute"', 'name="j2" type="planar"'))
    with pytest.raises(RobotFileError, match=r"planar\.urdf: joint 'j2' has type 'planar': dvqp "):
        Robot.from_urdf(path, points=["l2", "l3"], tool="probe")
    path.write_text(URDF.replace("</joint>", '<dynamics damping="x"/></joint>', 1))
    with pytest.raises(RobotFileError, match=r"planar\.urdf: cannot load URDF: .*\(Error: +damp"):
        Robot.from_urdf(path, points=["l2", "l3"], tool="probe")
    assert capfd.readouterr() == ("", "")
