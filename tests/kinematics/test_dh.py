import numpy as np
import pinocchio as pin
import pytest

from dvqp.errors import ParameterError, ShapeError
from dvqp.kinematics.dh import DHRow, check_transform, ndt13_table
from dvqp.kinematics.robot import NDT13_POINT_JOINTS, Robot
from tests.common import LINK_LENGTHS, random_configurations
from tests.kinematics.oracle import dh_transform, forward_dh


def pinocchio_frames(robot: Robot, q: np.ndarray) -> list[np.ndarray]:
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return [data.oMf[i].homogeneous for i in robot.frame_ids]


def test_pinocchio_forward_kinematics_equals_plain_dh_product(robot: Robot) -> None:
    table, tool = ndt13_table(LINK_LENGTHS)
    for q in random_configurations(50, seed=1, spread=np.pi):
        ref = forward_dh(table, q, tool)
        expected = [ref[j - 1] for j in NDT13_POINT_JOINTS] + [ref[-1], ref[1]]  # tool, rail
        for got, want in zip(pinocchio_frames(robot, q), expected, strict=True):
            np.testing.assert_allclose(got, want, atol=1e-12, rtol=0)


def test_general_dh_table_with_offsets_matches_plain_product() -> None:
    rng = np.random.default_rng(7)
    table = [
        DHRow(*rng.uniform(-0.3, 0.3, 2), rng.uniform(-np.pi, np.pi), rng.uniform(-1, 1))
        for _ in range(6)
    ]
    tool = np.eye(4)
    tool[:3, 3] = [0.01, 0.02, 0.05]
    robot = Robot.from_dh(table, tool, point_joints=(2, 4, 6))
    for q in rng.uniform(-np.pi, np.pi, size=(20, 6)):
        ref = forward_dh(table, q, tool)
        expected = [ref[1], ref[3], ref[5], ref[6]]
        for got, want in zip(pinocchio_frames(robot, q), expected, strict=True):
            np.testing.assert_allclose(got, want, atol=1e-12, rtol=0)


def test_dh_transform_is_rz_tz_tx_rx() -> None:
    row = DHRow(d=0.2, a=0.3, alpha=0.4)
    th = 0.7
    rz = np.eye(4)
    rz[:2, :2] = [[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]
    tz = np.eye(4)
    tz[2, 3] = 0.2
    tx = np.eye(4)
    tx[0, 3] = 0.3
    rx = np.eye(4)
    rx[1:3, 1:3] = [[np.cos(0.4), -np.sin(0.4)], [np.sin(0.4), np.cos(0.4)]]
    np.testing.assert_allclose(dh_transform(row, th), rz @ tz @ tx @ rx, atol=1e-15)


def test_ndt13_table_rejects_wrong_number_of_lengths_and_negative_lengths() -> None:
    with pytest.raises(ShapeError, match="link_lengths"):
        ndt13_table([0.1] * 6)
    with pytest.raises(ParameterError, match="link_lengths"):
        ndt13_table([0.1] * 6 + [-0.1])


def test_check_transform_rejects_non_rigid_matrix() -> None:
    with pytest.raises(ShapeError):
        check_transform("tool", np.eye(3))
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(ParameterError, match="tool"):
        check_transform("tool", bad)
