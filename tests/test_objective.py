"""The objective's terms and their sum: values, gradients against finite differences."""

import numpy as np
import pytest

from dvqp import KinematicState, Objective, Obstacle, ObstacleSet, Robot, Term
from dvqp.errors import ParameterError, ShapeError
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel
from tests.common import PIPE_RADIUS, central_difference, objective_with, random_configurations

R = PIPE_RADIUS


TERMS = {"orbital": 0, "obstacle_points": 1, "obstacle_links": 2}


def part(objective: Objective, term: str, state: KinematicState) -> Term:
    """One of the paper's terms by name, or ``"evaluate"`` for the sum."""
    if term == "evaluate":
        return objective.evaluate(state)
    return objective.terms[TERMS[term]].evaluate(state)


def fd_check(robot: Robot, q: np.ndarray, term: str, objective: Objective) -> None:
    def value(v: np.ndarray) -> float:
        return part(objective, term, KinematicState.compute(robot, v, R)).value

    analytic = part(objective, term, KinematicState.compute(robot, q, R)).gradient
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
    assert part(objective, "obstacle_points", state).value < 0
    assert part(objective, "obstacle_links", state).value < 0
    assert np.abs(part(objective, "obstacle_links", state).gradient).max() > 0


def test_inactive_obstacles_add_nothing(robot: Robot, state0: KinematicState) -> None:
    far = objective_with([Obstacle(np.array([0.5, -1.0]), 0.05, 10.0)])
    none = objective_with([])
    assert far.evaluate(state0).value == none.evaluate(state0).value
    np.testing.assert_array_equal(far.evaluate(state0).gradient, none.evaluate(state0).gradient)
    assert part(far, "obstacle_points", state0).value == 0.0
    assert part(far, "obstacle_links", state0).value == 0.0


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
    assert part(objective, "obstacle_points", state).value == pytest.approx(
        0.5 * (0.02**2 - 0.03**2), rel=1e-3
    )
    fd_check(robot, q, "evaluate", objective)


def test_orbital_term_is_zero_at_the_orbital_level_and_negative_elsewhere(
    state0: KinematicState,
) -> None:
    h = state0.points[:, 2]
    gains = np.array([0.0, 3.0, 0.0, 0.0, 0.0])  # only point 2 counts
    at_level = OrbitalLevel(float(h[1]), k_height=gains)
    assert at_level.evaluate(state0).value == 0.0
    assert np.all(at_level.evaluate(state0).gradient == 0.0)
    off = OrbitalLevel(float(h[1]) + 0.01, k_height=gains)
    assert off.evaluate(state0).value == pytest.approx(-0.5 * 3.0 * 0.01**2)


def test_gradient_ascent_raises_w(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state))
    term = objective.evaluate(state)
    after = objective.evaluate(KinematicState.compute(robot, q0 + 1e-3 * term.gradient, R))
    assert after.value > term.value


def test_constructors_validate_gains_and_sizes(state0: KinematicState) -> None:
    with pytest.raises(ShapeError, match="k_height"):
        OrbitalLevel(0.08, k_height=[1.0, 2.0]).evaluate(state0)
    with pytest.raises(ParameterError, match="k_obstacle"):
        ObstaclePoints(ObstacleSet(), k_obstacle=-1.0)
    with pytest.raises(ParameterError, match="orbital_level"):
        OrbitalLevel(float("nan"))
    with pytest.raises(ParameterError, match="radius"):
        Obstacle(np.array([0.0, 0.0]), -0.1)
    with pytest.raises(ParameterError, match="gain"):
        Objective((), gain=-1.0)
    with pytest.raises(ParameterError, match=r"terms\[0\]"):
        Objective(("not a term",))  # type: ignore[arg-type]


def test_scalar_gains_equal_the_same_gain_per_point(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    obstacles = ObstacleSet(obstacles_around(state))
    for scalar, vector in [
        (OrbitalLevel(0.07, 2.0), OrbitalLevel(0.07, [2.0] * 5)),
        (ObstaclePoints(obstacles, 3.0), ObstaclePoints(obstacles, [3.0] * 5)),
        (ObstacleLinks(obstacles, 3.0), ObstacleLinks(obstacles, [3.0] * 5)),
    ]:
        a, b = scalar.evaluate(state), vector.evaluate(state)
        assert a.value == pytest.approx(b.value, rel=1e-14)
        np.testing.assert_allclose(a.gradient, b.gradient, rtol=1e-14, atol=1e-16)


def test_objective_is_the_sum_of_its_terms_and_is_computed_once_per_state(
    robot: Robot, q0: np.ndarray
) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state), gain=2.0)
    parts = [t.evaluate(state) for t in objective.terms]
    total = objective.evaluate(state)
    assert total.value == pytest.approx(sum(p.value for p in parts))
    np.testing.assert_allclose(total.gradient, sum(p.gradient for p in parts), atol=1e-15)
    assert objective.evaluate(state) is total
    np.testing.assert_allclose(objective.scaled_gradient(state), 2.0 * total.gradient)


def test_a_user_term_adds_to_the_paper_terms(robot: Robot, q0: np.ndarray) -> None:
    class JointCentering:
        """w = −½ ‖q − q_mid‖²: keeps the joints near the middle of their range."""

        name = "centering"

        def evaluate(self, state: KinematicState) -> Term:
            e = state.q - q0
            return Term(-0.5 * float(e @ e), -e)

    paper = objective_with([])
    both = Objective((*paper.terms, JointCentering()), gain=1.0)
    q = q0 + 0.05
    fd_check(robot, q, "evaluate", both)
    state = KinematicState.compute(robot, q, R)
    assert both.evaluate(state).value < paper.evaluate(state).value
