"""Obstacle dampers: which pairs add rows, rows equal to minus the clearance gradient, the
damper rule near and inside the margin, several dampers over different obstacle sets."""

import numpy as np
import pytest

from dvqp import Constraint, KinematicState, Obstacle, ObstacleSet, Robot
from dvqp.errors import ParameterError
from dvqp.geometry import proximity
from dvqp.geometry.shapes import Band, Inlet, Polygon
from dvqp.limits import ObstacleDamper
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import (
    DT,
    clearance_of,
    configurations,
    damper_rows,
    near_obstacles,
    problem_rows,
)
from tests.oracles.limits import damper_rhs, measure


def test_pairs_outside_the_influence_distance_add_no_row(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    obstacles = near_obstacles(state0)
    rows = stepping.rows(ObstacleDamper(obstacles, margin=0.005, influence=0.04), robot, q0)
    near = proximity(state0, obstacles)
    expected = int(np.sum(near.point_clearance < 0.04))
    t = near.link_t
    expected += int(np.sum((near.link_clearance < 0.04) & (t > 0) & (t < 1)))
    assert isinstance(rows, Constraint) and rows.rows == expected > 0
    assert not any(label.endswith("obstacles[2]") for label in rows.labels)
    far = ObstacleDamper(ObstacleSet([Obstacle(np.array([-0.5, -1.0]), 0.05)]), 0.005, 0.04)
    s = stepping.stepper(robot, q0, limits=[far], backend="daqp")
    s.prepare(np.zeros(4), DT)
    assert s.rows(far).rows == 0 and problem_rows(s) == 0  # type: ignore[union-attr]
    # its rows are there (6 points, 5 links, the rail point and the carriage), none applies
    assert s.problem().G.shape[0] == 2 * 5 + 1 + 2
    empty = stepping.stepper(robot, q0, limits=[ObstacleDamper(ObstacleSet())], backend="daqp")
    empty.prepare(np.zeros(4), DT)
    assert empty.problem().G is None  # no obstacle: no row at all


def test_damper_rows_are_minus_the_clearance_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    obstacles = near_obstacles(state)
    damper = ObstacleDamper(obstacles, influence=0.2)
    rows = stepping.rows(damper, robot, q0)
    assert isinstance(rows, Constraint)
    assert any(lab.startswith("link") for lab in rows.labels)
    assert any(lab.startswith("probe") for lab in rows.labels)
    for row, label in zip(rows.G, rows.labels, strict=True):
        fd = central_difference(
            lambda v, lab=label: clearance_of(robot, v, obstacles, lab), q0, 1e-7
        )
        np.testing.assert_allclose(-row, fd, rtol=1e-6, atol=1e-7)


def test_right_hand_side_is_the_damped_clearance_above_the_margin(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    obstacles = near_obstacles(state0)
    damper = ObstacleDamper(obstacles, margin=0.01, influence=0.2, gain=0.3)
    rows = stepping.rows(damper, robot, q0)
    found = measure(damper, state0)
    d = found.value[found.applies]
    room = d - 0.01
    geometric = 0.3 / DT * np.maximum(room, -1e-4)
    braking = np.sqrt(2.0 * damper.deceleration * np.maximum(room, 0.0))  # 1 m/s² by default
    assert damper.deceleration == 1.0
    np.testing.assert_allclose(rows.h, np.minimum(geometric, braking), rtol=0, atol=1e-12)  # type: ignore[union-attr]
    assert (braking < geometric).all()  # at 5 ms steps the braking speed binds from 0.1 mm on
    s = stepping.stepper(robot, q0, limits=[damper], backend="daqp")
    damper_rows(s, damper, q0, fd=True)


def test_pairs_deep_inside_the_margin_may_only_not_get_worse(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    p = state0.points[2, :2]
    inside = ObstacleSet([Obstacle(p + np.array([0.0, 0.01]), 0.03)])
    damper = ObstacleDamper(inside, gain=0.5)
    rows = stepping.rows(damper, robot, q0)
    d = np.array([clearance_of(robot, q0, inside, label) for label in rows.labels])  # type: ignore[union-attr]
    deep = d - damper.margin < -damper.tolerance
    assert deep.any() and np.all(rows.h[deep] == 0.0)  # type: ignore[union-attr]


def test_a_small_drift_below_the_margin_is_pulled_back(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    p = state0.points[2, :2]
    obstacles = ObstacleSet([Obstacle(p + np.array([0.0, 0.05]), 0.03)])
    d = float(proximity(state0, obstacles).point_clearance[0, 2])  # point 3's clearance, 2 cm
    damper = ObstacleDamper(obstacles, margin=d + 5e-5, gain=0.5)  # 0.05 mm inside
    rows = stepping.rows(damper, robot, q0)
    assert rows.labels[0] == "point3/obstacles[0]"  # type: ignore[union-attr]
    assert rows.h[0] == pytest.approx(max(-0.5 / DT * 5e-5, -damper.deceleration * DT))  # type: ignore[union-attr]
    assert rows.h[0] < 0.0  # type: ignore[union-attr]


def test_dampers_over_different_obstacle_sets_keep_each_its_own_rows(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    """Three obstacle dampers in one step, over sets that share shapes: each writes the rows of
    its own set (labels indexed in it), with its own margin, gain and deceleration."""
    a, b, c = near_obstacles(state0)
    p = state0.guarded[:, :2]
    d = Obstacle(p[5] + np.array([0.0, 0.05]), 0.03)  # near the probe
    dampers = [
        ObstacleDamper(ObstacleSet([a, b]), margin=0.01, influence=0.2, gain=0.3),
        ObstacleDamper(
            ObstacleSet([b, d, c]), margin=0.02, influence=0.1, gain=0.8, deceleration=0.2
        ),
        ObstacleDamper(ObstacleSet([d]), margin=0.0, influence=0.3, deceleration=np.inf),
    ]
    s = stepping.stepper(robot, q0, limits=dampers, backend="daqp")
    total = 0
    for q in [q0, *configurations(robot, q0, 4, seed=3, spread=0.05)]:
        rows = [damper_rows(s, damper, q, 0.01, fd=q is q0) for damper in dampers]
        assert all(r.rows > 0 for r in rows)
        assert any(label.startswith("point3/obstacles[0]") for label in rows[0].labels)
        assert any(label.startswith("probe/obstacles[1]") for label in rows[1].labels)
        problem = s.problem()
        applies = np.isfinite(problem.h)
        stacked = np.vstack([r.G for r in rows])
        np.testing.assert_array_equal(problem.G[applies], stacked)  # all in one problem
        np.testing.assert_array_equal(problem.h[applies], np.concatenate([r.h for r in rows]))
        total += applies.sum()
    assert total > 0


def mixed_shapes(state: KinematicState) -> ObstacleSet:
    """A band 3 cm above point 3, a polygon near link 4 and an inlet beside link 1 (the links
    stay outside: the deepest point of a link inside a polygon can sit on a kink, where the
    clearance has no gradient)."""
    g = state.guarded[:, :2]
    box = np.array([[-0.03, -0.02], [0.035, -0.025], [0.03, 0.03], [-0.025, 0.02]])
    return ObstacleSet(
        [
            Band(g[2, 1] + 0.03, g[2, 1] + 0.08),
            Polygon(g[4] + box + np.array([0.0, 0.06])),
            Inlet(g[0] + np.array([0.09, 0.1]), 0.06, PIPE_RADIUS),
        ]
    )


def test_every_shape_class_gives_rows_of_minus_its_clearance_gradient(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    damper = ObstacleDamper(mixed_shapes(state0), margin=0.005, influence=0.1)
    s = stepping.stepper(robot, q0, limits=[damper], backend="daqp")
    seen = set()
    for q in [q0, *configurations(robot, q0, 3, seed=4, spread=0.03)]:
        rows = damper_rows(s, damper, q, fd=True)
        seen |= {label.split("/")[1] for label in rows.labels}
    assert seen == {"obstacles[0]", "obstacles[1]", "obstacles[2]"}


def test_an_obstacle_across_the_seam_acts_on_a_point_on_the_other_side(
    robot: Robot, q0: np.ndarray
) -> None:
    q = q0.copy()
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    q[0] += (np.pi * PIPE_RADIUS - 0.01 - state.points[2, 0]) / PIPE_RADIUS
    state = KinematicState.compute(robot, q, PIPE_RADIUS)
    assert state.points[2, 0] == pytest.approx(np.pi * PIPE_RADIUS - 0.01, abs=1e-6)
    centre = np.array([-np.pi * PIPE_RADIUS + 0.02, state.points[2, 1]])  # 3 cm away, across
    damper = ObstacleDamper(ObstacleSet([Obstacle(centre, 0.01)]), margin=0.005)
    s = stepping.stepper(robot, q, limits=[damper], backend="daqp")
    rows = damper_rows(s, damper, q, fd=True)
    at = rows.labels.index("point3/obstacles[0]")
    assert rows.h[at] == pytest.approx(damper_rhs(np.array([0.02]), 0.005, 0.5, DT, 1e-4, 1.0)[0])


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="influence"):
        ObstacleDamper(ObstacleSet(), margin=0.05, influence=0.01)
    with pytest.raises(ParameterError, match="influence"):
        ObstacleDamper(ObstacleSet(), influence=np.inf)
    with pytest.raises(ParameterError, match="gain"):
        ObstacleDamper(ObstacleSet(), gain=1.5)
    with pytest.raises(ParameterError, match="margin"):
        ObstacleDamper(ObstacleSet(), margin=-0.01)
    with pytest.raises(ParameterError, match="deceleration"):
        ObstacleDamper(ObstacleSet(), deceleration=0.0)
