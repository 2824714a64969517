"""The paper's baseline: eq. 18, its weighted form, soft tasks and singular tasks.

The compiled step (:func:`dvqp.resolution.pinv.pinv_step`, and the baseline's
:class:`~dvqp.Stepper`) is compared with the formula written out in NumPy and with the KKT
minimiser (``tests/oracles/resolution.py``).
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import (
    Objective,
    PseudoinverseResolver,
    Robot,
    Stepper,
    StepSpec,
    Task,
    TaskRows,
    ToolTask,
    simulate,
)
from dvqp.errors import ParameterError, ShapeError, SingularConfigurationError
from dvqp.resolution.pinv import SINGULAR, pinv_step, symmetric_eigen
from tests.common import PIPE_RADIUS, Q0, random_configurations, spec_with
from tests.oracles.resolution import eq18, frames, kkt, nested

DT = 0.005
COMMAND = np.array([0.02, 0.01, 0.0, 0.1])


def compiled(
    jac: np.ndarray,
    xdot: np.ndarray,
    g: np.ndarray,
    weights: np.ndarray,
    metric: np.ndarray | None = None,
    damping: float = 0.0,
) -> tuple[int, np.ndarray]:
    """``pinv_step`` on its own, one level: its status and ``Q̇`` (the dense ``metric`` if
    given)."""
    out, info = np.full(jac.shape[1], np.nan), np.zeros(3)
    P = np.eye(jac.shape[1]) if metric is None else metric
    levels = np.array([0, jac.shape[0]], dtype=np.int64)
    status = pinv_step(
        np.ascontiguousarray(jac),
        xdot,
        levels,
        np.ones(jac.shape[0]),
        -g,
        weights,
        P,
        metric is not None,
        damping,
        info,
        out,
    )
    return int(status), out


def baseline(robot: Robot, spec: StepSpec, damping: float = 0.0) -> Stepper:
    """The baseline's compiled step of ``spec``, started at the paper's configuration."""
    s = Stepper(robot, PIPE_RADIUS, PseudoinverseResolver(spec, damping), Q0, DT)
    s.start(Q0)
    return s


def set_gradient(spec: StepSpec, g: np.ndarray) -> None:
    """The ``g`` that ``spec``'s :class:`~tests.common.ConstantGradient` returns from now on."""
    spec.objective.terms[0].gradient[:] = g  # type: ignore[attr-defined]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_step_tracks_the_command_and_equals_the_qp_minimiser(seed: int, weighted: bool) -> None:
    rng = np.random.default_rng(seed)
    jac = rng.normal(size=(4, 13))
    xdot, g = rng.normal(size=4), rng.normal(size=13)
    w = rng.uniform(0.2, 5.0, 13) if weighted else np.ones(13)
    status, qdot = compiled(jac, xdot, g, w)
    assert status == -1
    np.testing.assert_allclose(jac @ qdot, xdot, atol=1e-10)
    np.testing.assert_allclose(qdot, kkt(jac, xdot, g, np.diag(w)), atol=1e-9)
    np.testing.assert_allclose(qdot, eq18(jac, xdot, g, w), atol=1e-9)


@pytest.mark.parametrize("weighted", [False, True])
def test_the_baseline_step_is_eq18_at_the_arms_configurations(robot: Robot, weighted: bool) -> None:
    rng = np.random.default_rng(2)
    w = rng.uniform(0.5, 2.0, 13) if weighted else np.ones(13)
    spec = spec_with(np.zeros(13), w)
    s = baseline(robot, spec)
    for q in random_configurations(8, seed=3):
        g, xdot = rng.normal(size=13), rng.normal(size=4)
        set_gradient(spec, g)
        assert s.load(q)
        np.testing.assert_array_equal(s.objective.gradient, g)  # λ = 1
        found = s.resolve(xdot, DT)
        assert found.success and found.status == "optimal"
        expected = eq18(np.array(s.state.tool_jacobian), xdot, g, None if not weighted else w)
        np.testing.assert_allclose(s.x, expected, rtol=0, atol=1e-10 * np.abs(expected).max())


def test_the_step_moves_the_tool_at_the_commanded_velocity(robot: Robot) -> None:
    """To first order in the step, measured on Pinocchio's frames (not dvqp's Jacobian)."""
    spec = spec_with(np.linspace(-1, 1, 13))
    s, h = baseline(robot, spec), 1e-6
    for q in random_configurations(4, seed=8, spread=0.3):
        assert s.load(q)
        s.resolve(COMMAND, h)
        assert s.move()
        assert s.motion[0] < 1e-12  # ‖J̄ Q̇ − ẋ‖∞ of the integrated step
        np.testing.assert_allclose(s.state.q, q + h * s.x, rtol=0, atol=1e-15)
        before, after = frames(robot, q, PIPE_RADIUS), frames(robot, s.state.q, PIPE_RADIUS)
        np.testing.assert_allclose((after.tool - before.tool) / h, COMMAND, atol=1e-5)


def test_null_space_part_does_not_disturb_the_task(robot: Robot) -> None:
    rng = np.random.default_rng(4)
    xdot, g = rng.normal(size=4), rng.normal(size=13)
    spec = spec_with(np.zeros(13), rng.uniform(0.5, 2.0, 13))
    s = baseline(robot, spec)
    s.resolve(xdot, DT)
    without = s.x.copy()
    set_gradient(spec, g)
    s.load(Q0)
    s.resolve(xdot, DT)
    jac = np.array(s.state.tool_jacobian)
    np.testing.assert_allclose(jac @ (s.x - without), 0.0, atol=1e-10)
    np.testing.assert_allclose(jac @ s.x, xdot, atol=1e-10)
    assert np.abs(s.x - without).max() > 1e-3


class Zero(Task):
    """A hard task of one zero row: the stacked task Jacobian is rank deficient."""

    name = "zero"

    def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
        return TaskRows(np.zeros((1, state.n)), np.zeros(1))


def test_a_dependent_row_is_met_in_least_squares_undamped_and_damped_as_eq18(
    robot: Robot,
) -> None:
    spec = spec_with(np.linspace(-1, 1, 13)).with_extra(tasks=[Zero()])
    s = baseline(robot, spec)
    assert s.resolve(COMMAND, DT).success  # the zero row: rank deficient, met (0 = 0)
    tool = np.array(s.state.tool_jacobian)
    np.testing.assert_allclose(s.x, eq18(tool, COMMAND, np.linspace(-1, 1, 13)), atol=1e-10)
    s = baseline(robot, spec, damping=1e-2)
    assert s.resolve(COMMAND, DT).success
    jac = np.vstack([s.state.tool_jacobian, np.zeros((1, 13))])
    expected = eq18(jac, np.r_[COMMAND, 0.0], np.linspace(-1, 1, 13), damping=1e-2)
    np.testing.assert_allclose(s.x, expected, atol=1e-10)
    status, _ = compiled(jac, np.r_[COMMAND, 1.0], np.zeros(13), np.ones(13))
    assert status == -1  # inconsistent (0 = 1): least squares all the same


def test_a_nearly_singular_row_below_the_rank_tolerance_is_dropped() -> None:
    jac = np.eye(4, 13)
    jac[3, 3] = 1e-6  # the Gram matrix's eigenvalues: 1 and 1e-12 < 1e-10 · 1: rank 3
    status, qdot = compiled(jac, np.ones(4), np.zeros(13), np.ones(13))
    assert status == -1
    np.testing.assert_allclose(qdot, eq18(jac[:3], np.ones(3), np.zeros(13)), atol=1e-12)
    jac[3, 3] = 1e-4  # 1e-8: still resolved, and exactly
    status, qdot = compiled(jac, np.ones(4), np.zeros(13), np.ones(13))
    assert status == -1
    np.testing.assert_allclose(qdot, eq18(jac, np.ones(4), np.zeros(13)), rtol=1e-9)
    jac[3, 3] = np.nan
    status, _ = compiled(jac, np.ones(4), np.zeros(13), np.ones(13))
    assert status == SINGULAR


def test_bad_inputs_raise_typed_errors(robot: Robot, q0: np.ndarray) -> None:
    with pytest.raises(ParameterError, match="weights"):
        spec_with(np.zeros(13), weights=[0.0] * 13)
    with pytest.raises(ShapeError, match="weights"):
        baseline(robot, spec_with(np.zeros(13), [1.0] * 12))
    with pytest.raises(ParameterError, match="damping"):
        PseudoinverseResolver(spec_with(np.zeros(13)), damping=-1.0)
    resolver = PseudoinverseResolver(spec_with(np.zeros(13)))
    with pytest.raises(ShapeError, match="commands"):
        simulate(robot, PIPE_RADIUS, resolver, q0, np.zeros((5, 3)), DT)
    with pytest.raises(ParameterError, match="commands"):
        simulate(robot, PIPE_RADIUS, resolver, q0, [[np.nan, 0, 0, 0]], DT)


def test_the_step_refuses_a_command_of_the_wrong_shape_or_not_finite(robot: Robot) -> None:
    s = baseline(robot, spec_with(np.zeros(13)))
    with pytest.raises(ShapeError, match="command"):
        s.resolve(np.zeros(3), DT)
    with pytest.raises(ParameterError, match="command"):
        s.resolve(np.array([np.nan, 0, 0, 0]), DT)


def test_a_small_damping_is_finite_on_a_rank_deficient_task() -> None:
    jac = np.zeros((4, 13))
    jac[0, 0] = 1.0  # rank 1
    g = np.linspace(-1, 1, 13)
    for mu in (1e-3, 1e-6, 1e-9):
        status, qdot = compiled(jac, np.ones(4), g, np.ones(13), damping=mu)
        assert status == -1 and np.all(np.isfinite(qdot))
        np.testing.assert_allclose(qdot, eq18(jac, np.ones(4), g, damping=mu), rtol=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000))
def test_dense_metric_step_equals_the_kkt_minimiser(seed: int) -> None:
    rng = np.random.default_rng(seed)
    jac, xdot, g = rng.normal(size=(4, 13)), rng.normal(size=4), rng.normal(size=13)
    root = rng.normal(size=(13, 13))
    metric = root @ root.T + 0.1 * np.eye(13)
    status, qdot = compiled(jac, xdot, g, np.ones(13), metric)
    assert status == -1
    np.testing.assert_allclose(qdot, kkt(jac, xdot, g, metric), atol=1e-8)
    diagonal = rng.uniform(0.5, 2.0, 13)
    _, dense = compiled(jac, xdot, g, np.ones(13), np.diag(diagonal))
    _, weighted = compiled(jac, xdot, g, diagonal)
    np.testing.assert_allclose(dense, weighted, atol=1e-10)


class HoldJoint(Task):
    """Soft task: joint ``i`` at ``speed`` (rad/s), weight ``w``."""

    name = "hold"
    hard = False

    def __init__(self, i: int, w: float, speed: float = 0.0) -> None:
        self.i, self.w, self.speed = i, w, speed

    def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
        row = np.zeros((1, state.n))
        row[0, self.i] = 1.0
        return TaskRows(row, np.array([self.speed]), self.w)


def test_a_soft_task_enters_the_baseline_as_a_metric(robot: Robot) -> None:
    rng = np.random.default_rng(7)
    g = rng.normal(size=13)
    free = baseline(robot, spec_with(g))
    free.resolve(COMMAND, DT)
    spec = spec_with(g).with_extra(tasks=[HoldJoint(5, 1e6)])
    held = baseline(robot, spec)
    held.resolve(COMMAND, DT)
    assert abs(free.x[5]) > 1e-3 and abs(held.x[5]) < 1e-5
    jac = np.array(held.state.tool_jacobian)
    np.testing.assert_allclose(jac @ held.x, COMMAND, atol=1e-10)
    with pytest.raises(ParameterError, match="damping"):
        baseline(robot, spec, damping=1e-3)


def test_the_soft_tasks_step_is_the_minimiser_of_their_cost(robot: Robot) -> None:
    """``½ Q̇ᵀ (W + Σ w JᵀJ) Q̇ − (g + Σ w Jᵀ v)ᵀ Q̇`` under the hard task, at every state."""
    rng = np.random.default_rng(9)
    g, w = rng.normal(size=13), rng.uniform(0.5, 2.0, 13)
    tasks = [HoldJoint(2, 3.0, 0.3), HoldJoint(7, 50.0, -0.1), HoldJoint(2, 0.5, 0.1)]
    s = baseline(robot, spec_with(g, w).with_extra(tasks=tasks))
    for q in random_configurations(4, seed=10, spread=0.3):
        assert s.load(q)
        s.resolve(COMMAND, DT)
        metric, pull = np.diag(w), g.copy()
        for t in tasks:
            metric[t.i, t.i] += t.w
            pull[t.i] += t.w * t.speed
        expected = kkt(np.array(s.state.tool_jacobian), COMMAND, pull, metric)
        np.testing.assert_allclose(s.x, expected, atol=1e-10)


def test_a_metric_that_is_not_positive_definite_is_refused(robot: Robot) -> None:
    spec = spec_with(np.zeros(13)).with_extra(tasks=[HoldJoint(5, -2.0)])  # W + H: −1 at (5, 5)
    with pytest.raises(SingularConfigurationError, match="not positive definite"):
        baseline(robot, spec).resolve(COMMAND, DT)


def test_a_spec_needs_a_hard_task_and_parts_derived_from_dvqps() -> None:
    with pytest.raises(ParameterError, match="hard task"):
        StepSpec((HoldJoint(0, 1.0),))
    with pytest.raises(ParameterError, match=r"limits\[0\].*dvqp\.Limit"):
        StepSpec((ToolTask(),), limits=("not a limit",))  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match=r"tasks\[1\].*dvqp\.Task"):
        StepSpec((ToolTask(), object()))  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match=r"terms\[0\].*ObjectiveTerm"):
        Objective((object(),))  # type: ignore[arg-type]


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 13))
def test_jacobi_rotations_give_the_eigen_decomposition_of_a_symmetric_matrix(
    seed: int, m: int
) -> None:
    rng = np.random.default_rng(seed)
    half = rng.normal(size=(m, m))
    a = half @ half.T if seed % 2 else half + half.T  # definite, or not
    vectors, decomposed = np.empty((m, m)), a.copy()
    assert symmetric_eigen(decomposed, vectors)
    values = np.diag(decomposed)
    np.testing.assert_allclose(np.sort(values), np.linalg.eigvalsh(a), atol=1e-10 * np.abs(a).max())
    np.testing.assert_allclose(
        vectors @ np.diag(values) @ vectors.T, a, atol=1e-10 * np.abs(a).max()
    )
    np.testing.assert_allclose(vectors.T @ vectors, np.eye(m), atol=1e-12)
    nan = a.copy()
    nan[0, 0] = np.nan
    assert not symmetric_eigen(nan, vectors)


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 10_000),
    st.lists(st.tuples(st.integers(1, 4), st.integers(0, 2)), min_size=1, max_size=4),
    st.booleans(),
)
def test_a_level_that_cannot_be_met_is_met_in_weighted_least_squares_as_the_oracle_says(
    seed: int, shapes: list[tuple[int, int]], posture: bool
) -> None:
    """Levels of independent rows plus ``copies`` rows that repeat (scaled) or mix rows above
    or within them — dependent, and inconsistent where their right sides differ — and maybe a
    posture (the identity, 13 rows) last: each met in least squares, rows weighed, exactly as
    the SVD oracle's lexicographic minimiser."""
    rng = np.random.default_rng(seed)
    n = 13
    rows: list[np.ndarray] = []
    for fresh, copies in shapes:
        level = rng.normal(size=(fresh, n))
        earlier = np.vstack([*rows, level])
        mixes = rng.normal(size=(copies, earlier.shape[0])) @ earlier
        rows.append(np.vstack([level, mixes]))
    if posture:
        rows.append(np.eye(n))
    v = [rng.normal(size=r.shape[0]) for r in rows]
    weights = [rng.uniform(0.2, 5.0, r.shape[0]) for r in rows]
    g, w = rng.normal(size=n), rng.uniform(0.3, 3.0, n)
    A, b, row_w = np.vstack(rows), np.concatenate(v), np.concatenate(weights)
    breaks = np.cumsum([0, *(r.shape[0] for r in rows)]).astype(np.int64)
    out, info = np.zeros(n), np.zeros(3)
    status = pinv_step(A, b, breaks, row_w, -g, w, np.eye(n), False, 0.0, info, out)
    assert status == -1
    expected = nested(list(zip(rows, v, strict=True)), g, w, weights)
    np.testing.assert_allclose(out, expected, atol=1e-7 * max(1.0, np.abs(expected).max()))
