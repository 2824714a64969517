"""The paper's baseline: eq. 18, its weighted form, soft tasks and singular tasks."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import KinematicState, PseudoinverseResolver, Robot, StepSpec, TaskRows, ToolTask
from dvqp.errors import ParameterError, ShapeError, SingularConfigurationError
from dvqp.resolution.pinv import dense_pinv_step, weighted_pinv_step
from tests.common import PIPE_RADIUS, random_configurations, spec_with


def kkt_solution(jac: np.ndarray, xdot: np.ndarray, g: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Minimiser of ½ Q̇ᵀWQ̇ − gᵀQ̇ s.t. J̄Q̇ = ẋ from the KKT system (independent of the formula)."""
    n, m = jac.shape[1], jac.shape[0]
    kkt = np.block([[np.diag(w), jac.T], [jac, np.zeros((m, m))]])
    return np.linalg.solve(kkt, np.concatenate([g, xdot]))[:n]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_step_tracks_the_command_and_equals_the_qp_minimiser(seed: int, weighted: bool) -> None:
    rng = np.random.default_rng(seed)
    jac = rng.normal(size=(4, 13))
    xdot, g = rng.normal(size=4), rng.normal(size=13)
    w = rng.uniform(0.2, 5.0, 13) if weighted else np.ones(13)
    qdot = weighted_pinv_step(jac, xdot, g, 1.0 / w)
    np.testing.assert_allclose(jac @ qdot, xdot, atol=1e-10)
    np.testing.assert_allclose(qdot, kkt_solution(jac, xdot, g, w), atol=1e-9)


def test_paper_formula_eq18_is_the_unweighted_case(robot: Robot) -> None:
    rng = np.random.default_rng(2)
    for q in random_configurations(5, seed=3):
        jac = KinematicState.compute(robot, q, PIPE_RADIUS).tool_jacobian
        xdot, g = rng.normal(size=4), rng.normal(size=13)
        jp = jac.T @ np.linalg.inv(jac @ jac.T)
        eq18 = jp @ xdot + (np.eye(13) - jp @ jac) @ g
        np.testing.assert_allclose(weighted_pinv_step(jac, xdot, g, np.ones(13)), eq18, atol=1e-10)


def test_null_space_part_does_not_disturb_the_task(robot: Robot, state0: KinematicState) -> None:
    rng = np.random.default_rng(4)
    xdot = rng.normal(size=4)
    w = rng.uniform(0.5, 2.0, 13)
    with_g = PseudoinverseResolver(spec_with(rng.normal(size=13), w)).resolve(state0, xdot, 0.005)
    without = PseudoinverseResolver(spec_with(np.zeros(13), w)).resolve(state0, xdot, 0.005)
    jac = state0.tool_jacobian
    np.testing.assert_allclose(jac @ (with_g.qdot - without.qdot), 0.0, atol=1e-10)
    assert with_g.task_error < 1e-10 and np.abs(with_g.qdot - without.qdot).max() > 1e-3


def test_rank_deficient_task_raises_unless_damped() -> None:
    jac = np.zeros((4, 13))
    jac[:3, :3] = np.eye(3)  # fourth task row is zero: singular
    with pytest.raises(SingularConfigurationError, match="rank deficient"):
        weighted_pinv_step(jac, np.ones(4), np.zeros(13), np.ones(13))
    qdot = weighted_pinv_step(jac, np.ones(4), np.zeros(13), np.ones(13), damping=1e-2)
    assert np.all(np.isfinite(qdot))


def test_bad_inputs_raise_typed_errors(state0: KinematicState) -> None:
    with pytest.raises(ShapeError, match="command"):
        PseudoinverseResolver(spec_with(np.zeros(13))).resolve(state0, np.zeros(3), 0.005)
    with pytest.raises(ParameterError, match="command"):
        PseudoinverseResolver(spec_with(np.zeros(13))).resolve(state0, [np.nan, 0, 0, 0], 0.005)
    with pytest.raises(ParameterError, match="weights"):
        spec_with(np.zeros(13), weights=[0.0] * 13)
    with pytest.raises(ShapeError, match="weights"):
        PseudoinverseResolver(spec_with(np.zeros(13), [1.0] * 12)).resolve(
            state0, np.zeros(4), 0.005
        )
    with pytest.raises(ParameterError, match="damping"):
        PseudoinverseResolver(spec_with(np.zeros(13)), damping=-1.0)


def test_a_small_damping_is_finite_on_a_rank_deficient_task() -> None:
    jac = np.zeros((4, 13))
    jac[0, 0] = 1.0  # rank 1
    for mu in (1e-3, 1e-6, 1e-9):
        qdot = weighted_pinv_step(jac, np.ones(4), np.zeros(13), np.ones(13), damping=mu)
        assert np.all(np.isfinite(qdot))


def test_non_finite_inputs_are_refused_not_propagated() -> None:
    jac = np.eye(4, 13)
    with pytest.raises(ParameterError, match="finite"):
        weighted_pinv_step(jac, np.array([np.nan, 0, 0, 0]), np.zeros(13), np.ones(13))


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_dense_metric_step_equals_the_kkt_minimiser(seed: int) -> None:
    rng = np.random.default_rng(seed)
    jac, xdot, g = rng.normal(size=(4, 13)), rng.normal(size=4), rng.normal(size=13)
    root = rng.normal(size=(13, 13))
    metric = root @ root.T + 0.1 * np.eye(13)
    kkt = np.block([[metric, jac.T], [jac, np.zeros((4, 4))]])
    expected = np.linalg.solve(kkt, np.concatenate([g, xdot]))[:13]
    np.testing.assert_allclose(dense_pinv_step(jac, xdot, g, metric), expected, atol=1e-8)
    diagonal = rng.uniform(0.5, 2.0, 13)
    np.testing.assert_allclose(
        dense_pinv_step(jac, xdot, g, np.diag(diagonal)),
        weighted_pinv_step(jac, xdot, g, 1.0 / diagonal),
        atol=1e-10,
    )


class HoldJoint:
    """Soft task: joint ``i`` at rest, weight ``w``."""

    name = "hold"
    hard = False

    def __init__(self, i: int, w: float) -> None:
        self.i, self.w = i, w

    def compute(self, state: KinematicState, command: np.ndarray, dt: float) -> TaskRows:
        row = np.zeros((1, state.n))
        row[0, self.i] = 1.0
        return TaskRows(row, np.zeros(1), self.w)


def test_a_soft_task_enters_the_baseline_as_a_metric(state0: KinematicState) -> None:
    rng = np.random.default_rng(7)
    g, xdot = rng.normal(size=13), np.array([0.02, 0.01, 0.0, 0.1])
    free = PseudoinverseResolver(spec_with(g)).resolve(state0, xdot, 0.005)
    spec = spec_with(g).with_extra(tasks=[HoldJoint(5, 1e6)])
    held = PseudoinverseResolver(spec).resolve(state0, xdot, 0.005)
    assert abs(free.qdot[5]) > 1e-3 and abs(held.qdot[5]) < 1e-5
    assert held.task_error < 1e-10
    with pytest.raises(ParameterError, match="damping"):
        PseudoinverseResolver(spec, damping=1e-3).resolve(state0, xdot, 0.005)


def test_a_spec_needs_a_hard_task() -> None:
    with pytest.raises(ParameterError, match="hard task"):
        StepSpec((HoldJoint(0, 1.0),))
    with pytest.raises(ParameterError, match=r"limits\[0\]"):
        StepSpec((ToolTask(),), limits=("not a limit",))  # type: ignore[arg-type]
