import numpy as np
import pytest

from dvqp import KinematicState, Obstacle, Robot
from dvqp.limits import DamperParameters, joint_position_bounds, obstacle_dampers, surface_height
from dvqp.geometry.proximity import ObstacleSet, proximity
from dvqp.resolution.qp import StepConfig, build_step_qp
from tests.common import PIPE_RADIUS, central_difference

DT = 0.005


def near_obstacles(state: KinematicState) -> ObstacleSet:
    """One circle 2 cm from point 3, one crossing near link 4's middle, one far away."""
    p = state.points[:, :2]
    mid = 0.5 * (p[3] + p[4])
    return ObstacleSet(
        [
            Obstacle(p[2] + np.array([0.0, 0.05]), 0.03),
            Obstacle(mid + np.array([0.0, 0.045]), 0.03),
            Obstacle(np.array([-0.5, -1.0]), 0.05),
        ]
    )


def test_build_is_pure_and_has_the_documented_shape(robot: Robot, state0: KinematicState) -> None:
    config = StepConfig(robot, near_obstacles(state0), DamperParameters(min_height=0.02))
    g, xd = np.linspace(-1, 1, 13), np.array([0.01, 0.0, 0.0, 0.1])
    a = build_step_qp(config, state0, g, xd, DT)
    b = build_step_qp(config, state0, g, xd, DT)
    for name in ("P", "q", "A", "b", "G", "h", "lb", "ub"):
        np.testing.assert_array_equal(getattr(a.problem, name), getattr(b.problem, name))
    assert a.problem.n == 13 and a.problem.n_eq == 4
    np.testing.assert_array_equal(a.problem.q, -g)
    relaxed = build_step_qp(config, state0, g, xd, DT, relax_task=True)
    assert relaxed.problem.n == 17 and relaxed.relaxed
    np.testing.assert_array_equal(relaxed.problem.A[:, 13:], -np.eye(4))


def test_pairs_outside_the_influence_distance_add_no_row(state0: KinematicState) -> None:
    obstacles = near_obstacles(state0)
    params = DamperParameters(margin=0.005, influence=0.04)
    rows = obstacle_dampers(state0, obstacles, params, DT)
    near = proximity(state0, obstacles)
    expected = int(np.sum(near.point_clearance < 0.04))
    t = near.link_t
    expected += int(np.sum((near.link_clearance < 0.04) & (t > 0) & (t < 1)))
    assert rows.rows == expected > 0
    assert not any(label.endswith("obstacle3") for label in rows.labels)
    far = obstacle_dampers(
        state0, ObstacleSet([Obstacle(np.array([-0.5, -1.0]), 0.05)]), params, DT
    )
    assert far.rows == 0


def clearance_of(robot: Robot, q: np.ndarray, obstacles: ObstacleSet, label: str) -> float:
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    near = proximity(state, obstacles)
    kind, j = label.split("/obstacle")
    j = int(j) - 1
    if kind.startswith("point"):
        return float(near.point_clearance[j, int(kind[5:]) - 1])
    return float(near.link_clearance[j, int(kind[4:]) - 1])


def test_damper_rows_are_minus_the_clearance_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    obstacles = near_obstacles(state)
    rows = obstacle_dampers(state, obstacles, DamperParameters(influence=0.2), DT)
    assert any(lab.startswith("link") for lab in rows.labels)
    for row, label in zip(rows.G, rows.labels, strict=True):
        fd = central_difference(
            lambda v, lab=label: clearance_of(robot, v, obstacles, lab), q0, 1e-7
        )
        np.testing.assert_allclose(-row, fd, rtol=1e-6, atol=1e-7)


def test_height_rows_are_minus_the_height_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = surface_height(state, DamperParameters(min_height=0.02, gain=0.5), DT)
    fd = central_difference(
        lambda v: KinematicState.compute(robot, v, PIPE_RADIUS).points[:, 2], q0, 1e-7
    )
    np.testing.assert_allclose(-rows.G, fd, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(rows.h, 0.5 / DT * (state.points[:, 2] - 0.02))


def test_damper_right_hand_side_is_clipped_for_pairs_inside_the_margin(
    state0: KinematicState,
) -> None:
    p = state0.points[2, :2]
    inside = ObstacleSet([Obstacle(p + np.array([0.0, 0.01]), 0.03)])
    rows = obstacle_dampers(state0, inside, DamperParameters(), DT)
    assert rows.rows > 0 and np.all(rows.h >= 0.0)


def test_position_bounds_stop_exactly_at_the_limit(q0: np.ndarray) -> None:
    robot = Robot.ndt13([0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06], q_min=-0.5, q_max=0.5)
    q = np.clip(q0, -0.45, 0.45)
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    box = joint_position_bounds(robot, state, DT)
    np.testing.assert_allclose(q + DT * box.ub, 0.5)
    np.testing.assert_allclose(q + DT * box.lb, -0.5)


def test_config_validates_weights(robot: Robot) -> None:
    with pytest.raises(ValueError, match="weights"):
        StepConfig(robot, weights=np.zeros(13))
    with pytest.raises(ValueError, match="influence"):
        DamperParameters(margin=0.05, influence=0.01)
    with pytest.raises(ValueError, match="damper_gain"):
        DamperParameters(gain=1.5)
