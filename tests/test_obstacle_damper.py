"""Obstacle dampers: which pairs add rows, rows equal to minus the clearance gradient."""

import numpy as np
import pytest

from dvqp import KinematicState, Obstacle, ObstacleSet, Robot
from dvqp.errors import ParameterError
from dvqp.geometry import proximity
from dvqp.limits import ObstacleDamper
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT, near_obstacles


def test_pairs_outside_the_influence_distance_add_no_row(state0: KinematicState) -> None:
    obstacles = near_obstacles(state0)
    rows = ObstacleDamper(obstacles, margin=0.005, influence=0.04).compute(state0, DT)
    near = proximity(state0, obstacles)
    expected = int(np.sum(near.point_clearance < 0.04))
    t = near.link_t
    expected += int(np.sum((near.link_clearance < 0.04) & (t > 0) & (t < 1)))
    assert rows.rows == expected > 0
    assert not any(label.endswith("obstacle3") for label in rows.labels)
    far = ObstacleDamper(ObstacleSet([Obstacle(np.array([-0.5, -1.0]), 0.05)]), 0.005, 0.04)
    assert far.compute(state0, DT).rows == 0
    assert ObstacleDamper(ObstacleSet()).compute(state0, DT).rows == 0


def clearance_of(robot: Robot, q: np.ndarray, obstacles: ObstacleSet, label: str) -> float:
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    near = proximity(state, obstacles)
    kind, j = label.split("/obstacle")
    j = int(j) - 1
    if kind == "probe":
        return float(near.point_clearance[j, state.k])
    if kind == "holder":
        return float(near.link_clearance[j, state.k - 1])
    if kind.startswith("point"):
        return float(near.point_clearance[j, int(kind[5:]) - 1])
    return float(near.link_clearance[j, int(kind[4:]) - 1])


def test_damper_rows_are_minus_the_clearance_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    obstacles = near_obstacles(state)
    rows = ObstacleDamper(obstacles, influence=0.2).compute(state, DT)
    assert any(lab.startswith("link") for lab in rows.labels)
    assert any(lab.startswith("probe") for lab in rows.labels)
    for row, label in zip(rows.G, rows.labels, strict=True):
        fd = central_difference(
            lambda v, lab=label: clearance_of(robot, v, obstacles, lab), q0, 1e-7
        )
        np.testing.assert_allclose(-row, fd, rtol=1e-6, atol=1e-7)


def test_right_hand_side_is_the_damped_clearance_above_the_margin(
    state0: KinematicState,
) -> None:
    obstacles = near_obstacles(state0)
    damper = ObstacleDamper(obstacles, margin=0.01, influence=0.2, gain=0.3)
    d = damper.distances(state0)
    rows = damper.compute(state0, DT)
    room = d.value - 0.01
    geometric = 0.3 / DT * np.maximum(room, -1e-4)
    braking = np.sqrt(2.0 * damper.deceleration * np.maximum(room, 0.0))  # 1 m/s² by default
    np.testing.assert_allclose(rows.h, np.minimum(geometric, braking))
    assert (braking < geometric).all()  # at 5 ms steps the braking speed binds from 0.1 mm on
    np.testing.assert_array_equal(rows.G, -d.gradient)


def test_pairs_deep_inside_the_margin_may_only_not_get_worse(state0: KinematicState) -> None:
    p = state0.points[2, :2]
    inside = ObstacleSet([Obstacle(p + np.array([0.0, 0.01]), 0.03)])
    damper = ObstacleDamper(inside, gain=0.5)
    rows = damper.compute(state0, DT)
    d = damper.distances(state0).value
    deep = d - damper.margin < -damper.tolerance
    assert deep.any() and np.all(rows.h[deep] == 0.0)


def test_a_small_drift_below_the_margin_is_pulled_back(state0: KinematicState) -> None:
    p = state0.points[2, :2]
    start = ObstacleDamper(ObstacleSet([Obstacle(p + np.array([0.0, 0.05]), 0.03)]))
    d = float(start.distances(state0).value[0])  # point 3's clearance, 2 cm
    damper = ObstacleDamper(start.obstacles, margin=d + 5e-5, gain=0.5)  # 0.05 mm inside
    rows = damper.compute(state0, DT)
    assert rows.h[0] == pytest.approx(max(-0.5 / DT * 5e-5, -damper.deceleration * DT))
    assert rows.h[0] < 0.0


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="influence"):
        ObstacleDamper(ObstacleSet(), margin=0.05, influence=0.01)
    with pytest.raises(ParameterError, match="gain"):
        ObstacleDamper(ObstacleSet(), gain=1.5)
    with pytest.raises(ParameterError, match="margin"):
        ObstacleDamper(ObstacleSet(), margin=-0.01)
