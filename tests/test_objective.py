import numpy as np
import pytest

from dvqp import KinematicState, Objective, Obstacle, Robot
from dvqp.errors import ParameterError, ShapeError
from tests.common import PIPE_RADIUS, central_difference, objective_with, random_configurations

R = PIPE_RADIUS


def fd_check(robot: Robot, q: np.ndarray, term: str, objective: Objective) -> None:
    def value(v: np.ndarray) -> float:
        return getattr(objective, term)(KinematicState.compute(robot, v, R)).value

    analytic = getattr(objective, term)(KinematicState.compute(robot, q, R)).gradient
    fd = central_difference(value, q, 1e-7)
    scale = max(np.abs(fd).max(), 1e-12)
    np.testing.assert_allclose(analytic, fd, rtol=1e-6, atol=1e-6 * scale)


def obstacles_around(state: KinematicState) -> list[Obstacle]:
    """One circle holding point 3, one crossing link 4 (points 4-5) away from its ends."""
    p = state.points[:, :2]
    mid = 0.5 * (p[3] + p[4])
    normal = np.array([-(p[4] - p[3])[1], (p[4] - p[3])[0]])
    normal /= np.linalg.norm(normal)
    return [
        Obstacle(p[2] + np.array([0.01, -0.02]), 0.05, 10.0),
        Obstacle(mid + 0.02 * normal, 0.035, 5.0),
    ]


@pytest.mark.parametrize("term", ["orbital", "obstacle_points", "obstacle_links", "evaluate"])
def test_gradient_equals_finite_differences_with_obstacles_active(robot: Robot, term: str) -> None:
    for q in random_configurations(4, seed=5, spread=0.2):
        state = KinematicState.compute(robot, q, R)
        objective = objective_with(
            obstacles_around(state), k_height=[1, 2, 3, 4, 5], k_obstacle=[1, 2, 1, 2, 1]
        )
        fd_check(robot, q, term, objective)


def test_the_obstacles_of_the_check_are_really_active(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state))
    assert objective.obstacle_points(state).value < 0
    assert objective.obstacle_links(state).value < 0
    assert np.abs(objective.obstacle_links(state).gradient).max() > 0


def test_inactive_obstacles_add_nothing(robot: Robot, state0: KinematicState) -> None:
    far = objective_with([Obstacle(np.array([0.5, -1.0]), 0.05, 10.0)])
    none = objective_with([])
    assert far.evaluate(state0).value == none.evaluate(state0).value
    np.testing.assert_array_equal(far.evaluate(state0).gradient, none.evaluate(state0).gradient)
    assert far.obstacle_points(state0).value == 0.0 and far.obstacle_links(state0).value == 0.0


def test_obstacle_across_the_seam_acts_on_a_point_near_the_other_side(
    robot: Robot, q0: np.ndarray
) -> None:
    q = q0.copy()
    state = KinematicState.compute(robot, q, R)
    q[0] += (np.pi * R - 0.01 - state.points[2, 0]) / R  # point 3 just left of +πR
    state = KinematicState.compute(robot, q, R)
    assert state.points[2, 0] == pytest.approx(np.pi * R - 0.01, abs=1e-6)
    centre = np.array([-np.pi * R + 0.01, state.points[2, 1]])  # 0.02 m away across the seam
    objective = objective_with([Obstacle(centre, 0.03, 1.0)])
    assert objective.obstacle_points(state).value == pytest.approx(
        0.5 * (0.02**2 - 0.03**2), rel=1e-3
    )
    fd_check(robot, q, "evaluate", objective)


def test_orbital_term_is_zero_at_the_orbital_level_and_negative_elsewhere(
    state0: KinematicState,
) -> None:
    h = state0.points[:, 2]
    gains = np.array([0.0, 3.0, 0.0, 0.0, 0.0])  # only point 2 counts
    at_level = Objective(n_points=5, orbital_level=float(h[1]), k_height=gains)
    assert at_level.orbital(state0).value == 0.0
    assert np.all(at_level.orbital(state0).gradient == 0.0)
    off = Objective(n_points=5, orbital_level=float(h[1]) + 0.01, k_height=gains)
    assert off.orbital(state0).value == pytest.approx(-0.5 * 3.0 * 0.01**2)


def test_gradient_ascent_raises_w(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state))
    term = objective.evaluate(state)
    after = objective.evaluate(KinematicState.compute(robot, q0 + 1e-3 * term.gradient, R))
    assert after.value > term.value


def test_constructor_validates_gains_and_sizes(state0: KinematicState) -> None:
    with pytest.raises(ShapeError, match="k_height"):
        Objective(n_points=5, orbital_level=0.08, k_height=[1.0, 2.0])
    with pytest.raises(ParameterError, match="k_obstacle"):
        Objective(n_points=5, orbital_level=0.08, k_obstacle=-1.0)
    with pytest.raises(ParameterError, match="radius"):
        Obstacle(np.array([0.0, 0.0]), -0.1)
    with pytest.raises(ShapeError, match=r"state\.points"):
        Objective(n_points=4, orbital_level=0.08).evaluate(state0)
