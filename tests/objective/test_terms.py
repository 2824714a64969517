"""The step's objective against the old NumPy terms (:mod:`tests.oracles.objective`): each
compiled term and their sum over every shape class and bundled scene, with a user's terms
(NumPy or compiled) and shapes of one's own mixed in."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from dvqp import (
    Kernel,
    KinematicState,
    Objective,
    ObjectiveTerm,
    ObstacleSet,
    StepPlan,
    Term,
)
from dvqp.errors import ShapeError
from dvqp.geometry.shapes import Band, Circle
from dvqp.limits import ObstacleDamper
from dvqp.objective import ObstacleLinks
from tests import stepping
from tests.common import ORBITAL_LEVEL, central_difference
from tests.compiled_cases import (
    BUNDLED_WITH_OBSTACLES,
    Case,
    Dot,
    mixed_case,
    paper_robot,
    scene_case,
)
from tests.limit_fixtures import damper_rows
from tests.oracles.objective import evaluate, total

K_HEIGHT = np.array([100.0, 50.0, 80.0, 120.0, 90.0])
K_OBSTACLE = np.array([1.0, 2.0, 0.5, 1.5, 1.0])


def paper_objective(obstacles: ObstacleSet, vector_gains: bool) -> Objective:
    """The paper's objective, with gains per body point or scalar."""
    if vector_gains:
        return Objective.paper(ORBITAL_LEVEL, obstacles, k_height=K_HEIGHT, k_obstacle=K_OBSTACLE)
    return Objective.paper(ORBITAL_LEVEL, obstacles, k_height=100.0, k_obstacle=1.0)


def cases() -> list[tuple[str, Case]]:
    robot = paper_robot()
    found = [(name, scene_case(name)) for name in BUNDLED_WITH_OBSTACLES]
    found += [("mixed", mixed_case(robot)), ("mixed-seam", mixed_case(robot, seam=True))]
    found += [("mixed-heights", mixed_case(robot, heights=True))]
    return found


CASES = cases()


def assert_objective(case: Case, objective: Objective, configurations: np.ndarray) -> list[float]:
    """At each configuration the step's ``w`` and ``∂w/∂Q`` are the oracle's (1e-12);
    returns the values."""
    s = stepping.stepper(case.robot, case.q0, objective=objective, radius=case.radius)
    values = []
    for q in configurations:
        assert s.load(q)
        found, want = s.objective, total(objective.terms, case.state(q))
        assert found.value == pytest.approx(want.value, rel=0, abs=1e-12)
        np.testing.assert_allclose(found.gradient, want.gradient, rtol=0, atol=1e-12)
        values.append(found.value)
    return values


@pytest.mark.parametrize(("name", "case"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("vector_gains", [False, True], ids=["scalar", "per-point"])
def test_each_compiled_term_is_its_oracle(name: str, case: Case, vector_gains: bool) -> None:
    objective = paper_objective(case.obstacles, vector_gains)
    spread = 0.1 if name.startswith("mixed") else 0.3
    active = {}
    for term in objective.terms:
        values = assert_objective(case, Objective((term,)), case.configurations(30, spread))
        active[term.name] = sum(v != 0.0 for v in values)
    if name.startswith("mixed"):  # the obstacle terms were really exercised
        assert min(active.values()) >= 10, active


@pytest.mark.parametrize(("name", "case"), CASES, ids=[c[0] for c in CASES])
def test_the_objective_is_the_sum_of_the_oracle_terms(name: str, case: Case) -> None:
    objective = paper_objective(case.obstacles, vector_gains=True)
    assert_objective(case, objective, case.configurations(20, 0.1))


@pytest.mark.parametrize(
    ("seam", "heights"),
    [(False, False), (True, False), (False, True), (True, True)],
    ids=["mixed", "mixed-seam", "mixed-heights", "mixed-heights-seam"],
)
def test_the_gradient_is_the_derivative_of_w(seam: bool, heights: bool) -> None:
    """Central differences of the step's own ``w``, every shape class in the points' term;
    the links' term over the circles and bands (the deepest point of a link inside a polygon
    can sit on a kink, where the penalty has no derivative); with ``heights`` each obstacle a
    solid (parts over, beside and past the edge of them)."""
    case = mixed_case(paper_robot(), seam=seam, heights=heights)
    smooth = ObstacleSet([o for o in case.obstacles if type(o) in (Circle, Band)])
    paper = paper_objective(case.obstacles, vector_gains=True)
    terms = (paper.terms[0], paper.terms[1], ObstacleLinks(smooth, K_OBSTACLE))
    s = stepping.stepper(case.robot, case.q0, objective=Objective(terms), radius=case.radius)

    def w(v: np.ndarray) -> float:
        assert s.load(v)
        return s.objective.value

    links = 0
    for q in case.configurations(4, 0.1, seed=1):
        fd = central_difference(w, q, 1e-7)
        s.load(q)
        scale = max(np.abs(fd).max(), 1e-12)
        np.testing.assert_allclose(s.objective.gradient, fd, rtol=1e-6, atol=1e-6 * scale)
        links += evaluate(terms[2], case.state(q)).value != 0.0
    assert links > 0


def test_an_empty_obstacle_set_adds_only_the_orbital_level() -> None:
    case = mixed_case(paper_robot())
    objective = paper_objective(ObstacleSet(), vector_gains=True)
    q = case.configurations(2, 0.1)[1]
    (value,) = assert_objective(case, objective, q[None, :])
    assert value == evaluate(objective.terms[0], case.state(q)).value != 0.0


def test_an_objective_without_terms_is_zero() -> None:
    case = mixed_case(paper_robot())
    s = stepping.stepper(case.robot, case.q0, objective=Objective(()), backend="daqp")
    for q in case.configurations(3, 0.1):
        assert s.load(q)
        assert s.objective.value == 0.0 and not s.objective.gradient.any()
    s.prepare(np.zeros(4), 0.005)
    assert not s.problem().q.any()


class Centering(ObjectiveTerm):
    """A user's term in NumPy: ``−½ Σ c_i (q_i − m_i)²``."""

    name = "centering"

    def __init__(self, middle: np.ndarray, gains: np.ndarray) -> None:
        self.middle, self.gains = middle, gains

    def evaluate(self, state: KinematicState) -> Term:
        e = state.q - self.middle
        return Term(-0.5 * float(self.gains @ (e * e)), -self.gains * e)


@njit(cache=True)
def _reach(tool, tool_jacobian, value, gradient):  # type: ignore[no-untyped-def]
    """Add ``l_tool`` to ``w`` and ``∂l/∂Q`` to its gradient."""
    value[0] += tool[0]
    for c in range(gradient.shape[0]):
        gradient[c] += tool_jacobian[0, c]


class Reach(ObjectiveTerm):
    """A user's compiled term: ``w = l`` of the tool (its ``evaluate`` is the oracle's)."""

    name = "reach"

    def kernel(self, plan: StepPlan) -> Kernel:
        s = plan.state
        return Kernel(
            _reach, (s.tool, s.tool_jacobian, plan.objective_value, plan.objective_gradient)
        )

    def evaluate(self, state: KinematicState) -> Term:
        return Term(float(state.tool[0]), np.array(state.tool_jacobian[0]))


def test_a_user_s_terms_add_to_the_compiled_terms() -> None:
    """A NumPy term and a compiled term of one's own, between dvqp's: the sum of all."""
    case = mixed_case(paper_robot())
    paper = paper_objective(case.obstacles, vector_gains=True)
    rng = np.random.default_rng(3)
    centering = Centering(case.q0, rng.uniform(0.5, 2.0, 13))
    terms = (paper.terms[0], centering, paper.terms[1], Reach(), paper.terms[2])
    values = assert_objective(case, Objective(terms), case.configurations(10, 0.1))
    alone = assert_objective(case, paper, case.configurations(10, 0.1))
    assert all(a != b for a, b in zip(values, alone, strict=True))


def test_a_shape_of_one_s_own_counts_in_the_obstacle_terms() -> None:
    """A :class:`Dot` (measured by its NumPy methods) where a circle was: the same objective
    as dvqp's compiled circle, next to the compiled shapes."""
    case = mixed_case(paper_robot())
    shapes = list(case.obstacles)
    at = [i for i, shape in enumerate(shapes) if type(shape) is Circle]
    own = list(shapes)
    for i in at:
        circle = shapes[i]
        own[i] = Dot(circle.center, circle.radius, circle.weight)  # type: ignore[attr-defined]
    dvqp_s = paper_objective(ObstacleSet(shapes), vector_gains=True)
    ours = paper_objective(ObstacleSet(own), vector_gains=True)
    Dot.calls.clear()
    configurations = case.configurations(10, 0.1)
    values = assert_objective(case, ours, configurations)
    assert "point_distance" in Dot.calls and "segment_distance" in Dot.calls
    np.testing.assert_allclose(
        values, assert_objective(case, dvqp_s, configurations), rtol=0, atol=1e-12
    )


def test_terms_and_dampers_over_overlapping_sets_each_read_their_own_shapes() -> None:
    """The objective over some shapes, an obstacle damper over others (some shared), the
    recorded obstacles over a third set: each part sees its own."""
    case = mixed_case(paper_robot())
    shapes = list(case.obstacles)
    objective = paper_objective(ObstacleSet(shapes[:5]), vector_gains=True)
    damper = ObstacleDamper(ObstacleSet([shapes[4], shapes[2], shapes[7]]), 0.005, 0.1)
    s = stepping.stepper(
        case.robot,
        case.q0,
        objective=objective,
        limits=[damper],
        backend="daqp",
        obstacles=ObstacleSet(shapes[5:]),
    )
    for q in case.configurations(8, 0.1):
        assert s.load(q)
        want = total(objective.terms, case.state(q))
        assert s.objective.value == pytest.approx(want.value, rel=0, abs=1e-12)
        np.testing.assert_allclose(s.objective.gradient, want.gradient, rtol=0, atol=1e-12)
        damper_rows(s, damper, q)


def test_per_point_gains_of_the_wrong_length_are_refused_when_the_step_is_laid_out() -> None:
    case = mixed_case(paper_robot())
    for objective in (
        Objective.paper(ORBITAL_LEVEL, case.obstacles, k_height=[1.0, 2.0]),
        Objective.paper(ORBITAL_LEVEL, case.obstacles, k_obstacle=np.ones(6)),
    ):
        with pytest.raises(ShapeError, match=r"k_height|k_obstacle"):
            stepping.stepper(case.robot, case.q0, objective=objective)
