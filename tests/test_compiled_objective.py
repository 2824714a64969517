"""The objective terms' compiled kernels against their ``evaluate``: each adds its value and
gradient to the plan's, over the same configurations as the geometry tests."""

from __future__ import annotations

import numpy as np
import pytest

from dvqp import KinematicState, Objective, ObstacleSet
from dvqp.compiled import StepPlan
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel
from tests.common import ORBITAL_LEVEL, ConstantGradient
from tests.compiled_cases import (
    BUNDLED_WITH_OBSTACLES,
    Case,
    Dot,
    bound_kernels,
    mixed_case,
    paper_robot,
    scene_case,
)

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
    return found


def run_term(plan: StepPlan, kernels: list, state: KinematicState, start: float, g0) -> None:  # type: ignore[no-untyped-def, type-arg]
    """Load ``state``, set the accumulators to ``start`` and ``g0``, call the kernels."""
    plan.state.load(state)
    plan.objective_value[0] = start
    plan.objective_gradient[:] = g0
    for kernel in kernels:
        kernel.function(*kernel.args)


@pytest.mark.parametrize(("name", "case"), cases(), ids=[c[0] for c in cases()])
@pytest.mark.parametrize("vector_gains", [False, True], ids=["scalar", "per-point"])
def test_each_compiled_term_adds_its_reference_value_and_gradient(
    name: str, case: Case, vector_gains: bool
) -> None:
    objective = paper_objective(case.obstacles, vector_gains)
    spread = 0.1 if name.startswith("mixed") else 0.3
    rng = np.random.default_rng(1)
    active = dict.fromkeys((t.name for t in objective.terms), 0)
    for term in objective.terms:
        state0 = case.state(case.q0)
        plan = StepPlan(state0.n, state0.k, case.radius)
        kernels = bound_kernels(plan, lambda p, term=term: [term.kernel(p)])
        for q in case.configurations(30, spread):
            state = case.state(q)
            start, g0 = rng.normal(), rng.normal(size=state.n)
            run_term(plan, kernels, state, start, g0)
            want = term.evaluate(state)
            active[term.name] += want.value != 0.0
            assert plan.objective_value[0] - start == pytest.approx(want.value, rel=0, abs=1e-12)
            np.testing.assert_allclose(
                plan.objective_gradient - g0, want.gradient, rtol=0, atol=1e-12
            )
    if name.startswith("mixed"):  # the obstacle terms were really exercised
        assert min(active.values()) >= 10, active


@pytest.mark.parametrize(("name", "case"), cases(), ids=[c[0] for c in cases()])
def test_the_compiled_objective_sums_to_the_reference_objective(name: str, case: Case) -> None:
    objective = paper_objective(case.obstacles, vector_gains=True)
    state0 = case.state(case.q0)
    plan = StepPlan(state0.n, state0.k, case.radius)
    kernels = bound_kernels(plan, objective.kernels)  # type: ignore[arg-type]
    assert len(kernels) == len(plan.geometry) + 3
    for q in case.configurations(20, 0.1):
        state = case.state(q)
        run_term(plan, kernels, state, 0.0, 0.0)
        want = objective.evaluate(state)
        assert plan.objective_value[0] == pytest.approx(want.value, rel=0, abs=1e-12)
        np.testing.assert_allclose(plan.objective_gradient, want.gradient, rtol=0, atol=1e-12)


def test_an_empty_obstacle_set_adds_only_the_orbital_level() -> None:
    case = mixed_case(paper_robot())
    objective = paper_objective(ObstacleSet(), vector_gains=True)
    state = case.state(case.configurations(2, 0.1)[1])
    plan = StepPlan(state.n, state.k, case.radius)
    kernels = bound_kernels(plan, objective.kernels)  # type: ignore[arg-type]
    assert plan.geometry == [] and len(kernels) == 3
    run_term(plan, kernels, state, 0.0, 0.0)
    want = objective.evaluate(state)
    assert plan.objective_value[0] == pytest.approx(want.value, rel=0, abs=1e-12)
    np.testing.assert_allclose(plan.objective_gradient, want.gradient, rtol=0, atol=1e-12)
    assert want.value == objective.terms[0].evaluate(state).value


def test_an_objective_without_terms_has_no_kernels() -> None:
    assert Objective(()).kernels(StepPlan(13, 5, 0.254)) == []


def test_a_term_without_kernel_makes_the_objective_uncompiled() -> None:
    objective = Objective((OrbitalLevel(ORBITAL_LEVEL), ConstantGradient(np.zeros(13))))
    assert objective.kernels(StepPlan(13, 5, 0.254)) is None


def test_a_shape_without_kernel_makes_the_obstacle_terms_uncompiled() -> None:
    obstacles = ObstacleSet([Dot([0.3, 0.3], 0.05)])
    plan = StepPlan(13, 5, 0.254)
    assert ObstaclePoints(obstacles).kernel(plan) is None
    assert ObstacleLinks(obstacles).kernel(plan) is None
    assert paper_objective(obstacles, vector_gains=False).kernels(plan) is None


def test_per_point_gains_of_the_wrong_length_are_refused_when_the_plan_is_built() -> None:
    with pytest.raises(ValueError, match="k_height"):
        OrbitalLevel(ORBITAL_LEVEL, [1.0, 2.0]).kernel(StepPlan(13, 5, 0.254))
