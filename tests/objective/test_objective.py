"""The objective's terms and their sum, through the step: values against the old NumPy
formulas (:mod:`tests.oracles.objective`), gradients against finite differences."""

import numpy as np
import pytest

from dvqp import (
    KinematicState,
    Objective,
    ObjectiveTerm,
    Obstacle,
    ObstacleSet,
    Robot,
    Stepper,
    Term,
)
from dvqp.errors import ParameterError, ShapeError
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference, objective_with, random_configurations
from tests.oracles.objective import evaluate, total

R = PIPE_RADIUS

TERMS = {"orbital": 0, "obstacle_points": 1, "obstacle_links": 2}


def goal(objective: Objective, term: str) -> Objective:
    """One of the paper's terms by name, or ``"sum"`` for all of them."""
    if term == "sum":
        return objective
    return Objective((objective.terms[TERMS[term]],))


def w(s: Stepper, q: np.ndarray) -> float:
    assert s.load(q)
    return s.objective.value


def fd_check(robot: Robot, q: np.ndarray, objective: Objective) -> Term:
    """The step's ``w`` at ``q`` is the oracle's, its gradient the central differences of
    its own ``w``; returns it."""
    s = stepping.stepper(robot, q, objective=objective)
    found = s.objective
    want = total(objective.terms, KinematicState.compute(robot, q, R))
    assert found.value == pytest.approx(want.value, rel=0, abs=1e-12)
    np.testing.assert_allclose(found.gradient, want.gradient, rtol=0, atol=1e-12)
    fd = central_difference(lambda v: w(s, v), q, 1e-7)
    scale = max(np.abs(fd).max(), 1e-12)
    np.testing.assert_allclose(found.gradient, fd, rtol=1e-6, atol=1e-6 * scale)
    return found


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


@pytest.mark.parametrize("term", ["orbital", "obstacle_points", "obstacle_links", "sum"])
def test_gradient_equals_finite_differences_with_obstacles_active(robot: Robot, term: str) -> None:
    for q in random_configurations(4, seed=5, spread=0.2):
        state = KinematicState.compute(robot, q, R)
        objective = objective_with(
            obstacles_around(state), k_height=[1, 2, 3, 4, 5], k_obstacle=[1, 2, 1, 2, 1]
        )
        fd_check(robot, q, goal(objective, term))


def test_the_obstacles_of_the_check_are_really_active(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state))
    points = stepping.objective(goal(objective, "obstacle_points"), robot, q0)
    links = stepping.objective(goal(objective, "obstacle_links"), robot, q0)
    assert points.value < 0 and links.value < 0
    assert np.abs(links.gradient).max() > 0
    assert links.value == pytest.approx(evaluate(objective.terms[2], state).value, abs=1e-15)


def test_inactive_obstacles_add_nothing(robot: Robot, q0: np.ndarray) -> None:
    far = objective_with([Obstacle(np.array([0.5, -1.0]), 0.05, 10.0)])
    none = objective_with([])
    a, b = stepping.objective(far, robot, q0), stepping.objective(none, robot, q0)
    assert a.value == b.value
    np.testing.assert_array_equal(a.gradient, b.gradient)
    assert stepping.objective(goal(far, "obstacle_points"), robot, q0).value == 0.0
    assert stepping.objective(goal(far, "obstacle_links"), robot, q0).value == 0.0


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
    points = stepping.objective(goal(objective, "obstacle_points"), robot, q)
    assert points.value == pytest.approx(0.5 * (0.02**2 - 0.03**2), rel=1e-3)
    fd_check(robot, q, objective)


def test_orbital_term_is_zero_at_the_orbital_level_and_negative_elsewhere(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    h = state0.points[:, 2]
    gains = np.array([0.0, 3.0, 0.0, 0.0, 0.0])  # only point 2 counts
    at_level = stepping.objective([OrbitalLevel(float(h[1]), k_height=gains)], robot, q0)
    assert at_level.value == 0.0
    assert np.all(at_level.gradient == 0.0)
    off = stepping.objective([OrbitalLevel(float(h[1]) + 0.01, k_height=gains)], robot, q0)
    assert off.value == pytest.approx(-0.5 * 3.0 * 0.01**2)


def test_gradient_ascent_raises_w(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state))
    s = stepping.stepper(robot, q0, objective=objective)
    term = s.objective
    assert w(s, q0 + 1e-3 * term.gradient) > term.value


def test_constructors_validate_gains_and_sizes(robot: Robot, q0: np.ndarray) -> None:
    with pytest.raises(ShapeError, match="k_height"):  # refused when the step is laid out
        stepping.objective([OrbitalLevel(0.08, k_height=[1.0, 2.0])], robot, q0)
    with pytest.raises(ShapeError, match="k_obstacle"):
        stepping.objective([ObstacleLinks(ObstacleSet(), k_obstacle=[1.0] * 4)], robot, q0)
    with pytest.raises(ShapeError, match="k_height"):
        OrbitalLevel(0.08, k_height=np.ones((2, 5)))
    with pytest.raises(ParameterError, match="k_obstacle"):
        ObstaclePoints(ObstacleSet(), k_obstacle=-1.0)
    with pytest.raises(ParameterError, match="k_obstacle"):
        ObstacleLinks(ObstacleSet(), k_obstacle=[1.0, np.nan])
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
        a, b = stepping.objective([scalar], robot, q0), stepping.objective([vector], robot, q0)
        assert a.value != 0.0
        assert a.value == pytest.approx(b.value, rel=1e-14)
        np.testing.assert_allclose(a.gradient, b.gradient, rtol=1e-14, atol=1e-16)


def test_objective_is_the_sum_of_its_terms_and_the_gain_scales_the_step(
    robot: Robot, q0: np.ndarray
) -> None:
    state = KinematicState.compute(robot, q0, R)
    objective = objective_with(obstacles_around(state), gain=2.0)
    parts = [stepping.objective([t], robot, q0) for t in objective.terms]
    s = stepping.stepper(robot, q0, objective=objective, backend="daqp")
    found = s.objective
    assert found.value == pytest.approx(sum(p.value for p in parts), rel=1e-14)
    np.testing.assert_allclose(found.gradient, sum(p.gradient for p in parts), atol=1e-15)
    s.prepare(np.zeros(4), 0.005)
    np.testing.assert_allclose(s.problem().q, -2.0 * found.gradient, rtol=1e-15)


class JointCentering(ObjectiveTerm):
    """w = −½ ‖q − q_mid‖²: keeps the joints near the middle of their range."""

    name = "centering"

    def __init__(self, middle: np.ndarray) -> None:
        self.middle = middle

    def evaluate(self, state: KinematicState) -> Term:
        e = state.q - self.middle
        return Term(-0.5 * float(e @ e), -e)


def test_a_user_term_adds_to_the_paper_terms(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, R)
    paper = objective_with(obstacles_around(state))
    both = Objective((*paper.terms[:2], JointCentering(q0), paper.terms[2]), gain=1.0)
    q = q0 + 0.05
    found = fd_check(robot, q, both)  # against the oracle's sum and finite differences
    alone = stepping.objective(paper, robot, q)
    assert found.value == pytest.approx(alone.value - 0.5 * 13 * 0.05**2, rel=1e-12)
    np.testing.assert_allclose(found.gradient, alone.gradient - 0.05, atol=1e-12)
