"""The QP resolver: equal to eq. 18 without an active inequality, limits held, relaxed, braking
and failed steps."""

import numpy as np
import pytest

import solvers
from dvqp import (
    Bounds,
    JogSegment,
    Limit,
    Obstacle,
    ObstacleSet,
    PseudoinverseResolver,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    Task,
    TaskRows,
    ToolTask,
    jog_commands,
)
from dvqp import simulate as run
from dvqp.errors import BackendError
from dvqp.limits import (
    AccelerationLimit,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    SurfaceHeight,
)
from dvqp.objective import Objective
from dvqp.resolution.step import Resolver
from dvqp.step import advance
from tests.common import (
    LINK_LENGTHS,
    PIPE_RADIUS,
    Q0,
    objective_with,
    random_configurations,
    spec_with,
)
from tests.oracles.resolution import eq18, kkt

DT = 0.005

# Accuracy on Q̇ (rad/s) each backend reaches on the step QP with its dvqp settings.
AGREEMENT_TOLERANCE = {
    "daqp": 1e-9,
    "quadprog": 1e-9,
    "proxqp": 1e-6,
    "osqp": 1e-6,
    "clarabel": 1e-6,
    "piqp": 1e-6,
    "highs": 1e-5,
}
BACKENDS = [
    name
    for name in solvers.available_backends()
    if name.removeprefix("qpsolvers:") in AGREEMENT_TOLERANCE
]


def stepper(
    robot: Robot, spec: StepSpec, backend: object = "daqp", q0: np.ndarray | None = None
) -> Stepper:
    """The compiled step of ``spec`` on ``backend`` (``"pinv"``: the baseline), started."""
    resolver = PseudoinverseResolver(spec) if backend == "pinv" else QPResolver(spec, backend)  # type: ignore[arg-type]
    start = np.array(Q0) if q0 is None else q0
    s = Stepper(robot, PIPE_RADIUS, resolver, start, DT)
    s.start(start)
    return s


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("weighted", [False, True])
def test_qp_equals_the_pseudoinverse_step_when_no_inequality_is_active(
    robot: Robot, backend: str, weighted: bool
) -> None:
    rng = np.random.default_rng(17)
    weights = rng.uniform(0.5, 3.0, 13) if weighted else np.ones(13)
    # Loose limits, no obstacle, a floor far below: nothing is active.
    limits = (JointPositionLimit(robot), JointVelocityLimit(robot), SurfaceHeight(-1.0))
    tol = AGREEMENT_TOLERANCE[backend.removeprefix("qpsolvers:")]
    spec = spec_with(np.zeros(13), weights, limits)
    g = spec.objective.terms[0].gradient  # type: ignore[attr-defined]  # read at every state
    qp, pinv = stepper(robot, spec, backend), stepper(robot, spec, "pinv")
    for q in random_configurations(5, seed=23, spread=0.3):
        g[:], xdot = 0.1 * rng.normal(size=13), 0.02 * rng.normal(size=4)
        assert qp.load(q) and pinv.load(q)
        found = qp.resolve(xdot, DT)
        assert found.success and found.status == "optimal", found.status
        p = qp.problem()
        assert np.all(p.lb < qp.x - 1e-3) and np.all(qp.x < p.ub - 1e-3)  # the box is inactive
        assert np.all(p.G @ qp.x < p.h - 1e-3)
        expected = eq18(np.array(qp.state.tool_jacobian), xdot, g, weights)
        np.testing.assert_allclose(qp.x, expected, atol=tol, rtol=0)
        pinv.resolve(xdot, DT)  # the compiled baseline
        np.testing.assert_allclose(qp.x, pinv.x, atol=tol, rtol=0)


class Lean(Task):
    """Soft task: joint ``i`` at ``speed`` rad/s, weight ``w``."""

    name = "lean"
    hard = False

    def __init__(self, i: int, w: float, speed: float) -> None:
        self.i, self.w, self.speed = i, w, speed

    def compute(self, state, command, dt):  # type: ignore[no-untyped-def]
        return TaskRows(np.eye(1, state.n, self.i), np.array([self.speed]), self.w)


def test_with_soft_tasks_the_qp_equals_the_dense_metric_step(robot: Robot) -> None:
    rng = np.random.default_rng(29)
    tasks = [Lean(3, 4.0, 0.2), Lean(9, 0.5, -0.3)]
    limits = (JointPositionLimit(robot), JointVelocityLimit(robot), SurfaceHeight(-1.0))
    spec = spec_with(0.1 * rng.normal(size=13), limits=limits).with_extra(tasks=tasks)
    qp, pinv = stepper(robot, spec), stepper(robot, spec, "pinv")
    metric, pull = np.eye(13), spec.objective.terms[0].gradient.copy()  # type: ignore[attr-defined]
    for t in tasks:
        metric[t.i, t.i] += t.w
        pull[t.i] += t.w * t.speed
    for q in random_configurations(4, seed=31, spread=0.3):
        xdot = 0.02 * rng.normal(size=4)
        assert qp.load(q) and pinv.load(q)
        assert qp.resolve(xdot, DT).status == "optimal"
        pinv.resolve(xdot, DT)
        expected = kkt(np.array(qp.state.tool_jacobian), xdot, pull, metric)
        np.testing.assert_allclose(qp.x, expected, atol=1e-9, rtol=0)
        np.testing.assert_allclose(pinv.x, expected, atol=1e-9, rtol=0)


def limited_robot() -> Robot:
    lim = np.r_[np.inf, np.full(12, 1.2)]
    return Robot.ndt13(LINK_LENGTHS, q_min=-lim, q_max=lim, qd_max=1.0)


def paper_spec(
    robot: Robot, objective: Objective, obstacles: ObstacleSet, min_height: float, **damper: float
) -> StepSpec:
    """The paper's step with every limit of a scene."""
    limits = (
        JointPositionLimit(robot),
        JointVelocityLimit(robot),
        ObstacleDamper(obstacles, **damper),
        SurfaceHeight(min_height, damper.get("gain", 0.5)),
    )
    return StepSpec((ToolTask(),), objective, limits)


def clearance_history(traj, obstacles) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Clearance of every point to every obstacle along the run, shape (N+1, J, k)."""
    centers = np.array([o.center for o in obstacles])
    radii = np.array([o.radius for o in obstacles])
    d = traj.points[:, None, :, :2] - centers[None, :, None, :]
    return np.linalg.norm(d, axis=-1) - radii[None, :, None]


def test_limits_hold_along_a_jog_that_breaks_them_with_the_pseudoinverse(q0: np.ndarray) -> None:
    robot = limited_robot()
    obstacles = [
        Obstacle(np.array([0.19, 0.43]), 0.04, 10.0),
        Obstacle(np.array([0.08, 0.30]), 0.03, 10.0),
    ]
    objective = objective_with(obstacles)
    obstacle_set = objective.terms[1].obstacles  # type: ignore[attr-defined]
    # A floor of 0.06 m would hold the link chords so high that the last 40 ms of the command
    # become infeasible (relaxed, with a reported task error): 0.055 m leaves room.
    spec = paper_spec(robot, objective, obstacle_set, 0.055, margin=0.005, influence=0.05)
    cmd = jog_commands(
        [
            JogSegment(1.0, np.array([0.0, 0.06, 0, 0])),
            JogSegment(1.0, np.array([0.06, 0.0, -0.02, 0.3])),
        ],
        DT,
    )
    runs = {
        name: run(robot, PIPE_RADIUS, resolver, q0, cmd, DT, obstacles=obstacle_set)
        for name, resolver in (
            ("pinv", PseudoinverseResolver(spec)),
            ("qp", QPResolver(spec, "daqp")),
        )
    }
    qp, pinv = runs["qp"], runs["pinv"]
    assert qp.ok and qp.task_error.max() < 1e-9
    assert np.all(qp.q <= robot.q_max + 1e-9) and np.all(qp.q >= robot.q_min - 1e-9)
    assert np.all(np.abs(qp.qdot) <= robot.qd_max + 1e-6)  # solver tolerance
    # Height and clearance are linearised one step ahead: allow second-order overshoot only.
    assert qp.points[:, :, 2].min() >= 0.055 - 1e-4
    assert qp.min_clearance.min() > 0.0
    start_outside = clearance_history(qp, obstacles)[0] > 0
    assert np.all(clearance_history(qp, obstacles)[:, start_outside] > 0)
    # The baseline, same commands: it enters an obstacle.
    assert pinv.min_clearance.min() < -0.01


@pytest.mark.parametrize(
    "backend", [b for b in ("daqp", "osqp", "clarabel", "proxqp") if b in BACKENDS]
)
def test_an_infeasible_command_is_relaxed_with_a_reported_task_error(
    q0: np.ndarray, backend: str
) -> None:
    robot = limited_robot()
    spec = paper_spec(robot, objective_with([]), ObstacleSet(), 0.0)
    cmd = jog_commands([JogSegment(0.1, np.array([2.0, 0.0, 0.0, 0.0]))], DT)  # 2 m/s: too fast
    traj = run(robot, PIPE_RADIUS, QPResolver(spec, backend), q0, cmd, DT)
    commanded = slice(0, traj.brake_start)  # then the stop: the tool held still
    assert traj.ok and set(traj.status[commanded]) == {"relaxed"}
    assert traj.task_error[commanded].min() > 0.1
    assert np.all(np.abs(traj.qdot) <= robot.qd_max + 1e-6)  # solver tolerance


class CorruptingBackend:
    """Wraps a real backend and shifts its answer: the residual check must catch it."""

    def __init__(self) -> None:
        self._inner = solvers.make_backend("daqp")
        self.name, self.tolerance = "corrupt", self._inner.tolerance

    def solve(
        self, problem: solvers.Problem, initvals: np.ndarray | None = None
    ) -> solvers.Solution:
        good = self._inner.solve(problem, initvals)
        x = None if good.x is None else good.x + 1e-3
        return solvers.Solution.checked(
            problem, x, status="solved", backend=self.name, tolerance=self.tolerance
        )

    def reset(self) -> None:
        self._inner.reset()


def test_a_wrong_answer_reported_as_solved_is_not_used_and_the_arm_brakes(robot: Robot) -> None:
    s = stepper(robot, spec_with(np.zeros(13)), CorruptingBackend)
    moved = advance(s, np.array([0.01, 0, 0, 0]), DT)
    step = moved.step
    assert step.success and step.status == "braking" and np.all(step.qdot == 0.0)  # to rest
    assert step.task_error == pytest.approx(0.01)
    np.testing.assert_array_equal(s.state.q, Q0)


def test_braking_stays_inside_the_joint_bounds(robot: Robot) -> None:
    limit = AccelerationLimit(robot, 2.0)
    s = stepper(robot, spec_with(np.zeros(13), limits=(limit,)), CorruptingBackend)
    s.observe(np.full(13, 0.5), DT)  # moving at 0.5 rad/s: may slow by 2·DT per step
    np.testing.assert_array_equal(limit.previous, 0.5)
    found = s.resolve(np.array([0.01, 0, 0, 0]), DT)
    assert found.success and found.status == "braking"
    np.testing.assert_allclose(s.x, 0.5 - 2.0 * DT)


class _Box(Limit):
    """A user's bounds limit (rad/s)."""

    name = "box"

    def __init__(self, lb: float, ub: float) -> None:
        self.lb, self.ub = lb, ub

    def compute(self, state, dt):  # type: ignore[no-untyped-def]
        return Bounds(np.full(state.n, self.lb), np.full(state.n, self.ub))


def test_bounds_that_cross_fail_the_step_and_name_the_joint(robot: Robot) -> None:
    s = stepper(robot, spec_with(np.zeros(13), limits=(_Box(0.2, 1.0), _Box(-1.0, 0.1))))
    why = "failed: the bounds on joint1's velocity cross (0.2 > 0.1 rad/s)"
    assert s.prepare(np.zeros(4), DT) == 0  # the first joint whose bounds cross
    found = s.resolve(np.zeros(4), DT)
    assert not found.success and found.status == why
    moved = advance(s, np.zeros(4), DT)
    assert not moved.step.success and moved.step.status == why
    assert np.all(moved.step.qdot == 0.0) and moved.substeps == 1
    np.testing.assert_array_equal(s.state.q, Q0)  # the arm holds still


def test_unknown_backend_lists_the_installed_ones(robot: Robot) -> None:
    with pytest.raises(BackendError, match=r"installed: .*daqp"):
        QPResolver(spec_with(np.zeros(13)), "nosuchsolver")


class OwnQP(Resolver):
    """A resolver of its own, no subclass of the built-in ones: its steps call a DAQP
    :class:`QPSolver` it makes itself (``solver``), and it counts them."""

    name = "own-qp"

    def __init__(self, spec: StepSpec) -> None:
        super().__init__(spec)
        self.inner, self.made = QPResolver(spec, "daqp"), 0

    def solver(self, qp, task_weight, levels, row_weights):  # type: ignore[no-untyped-def]
        self.made += 1
        return self.inner.solver(qp, task_weight, levels, row_weights)


class OwnBaseline(Resolver):
    """A resolver of its own whose step is the baseline's, damped (``baseline_damping``)."""

    name = "own-baseline"
    holds_limits = False

    def baseline_damping(self) -> float:
        return 0.01


def test_a_resolver_of_its_own_joins_the_step_through_its_hooks_not_its_type(
    q0: np.ndarray,
) -> None:
    """The step asks a resolver for its QP solver and whether its step is the baseline's: a
    class that derives from neither built-in resolver runs as the one it delegates to."""
    robot = limited_robot()
    spec = paper_spec(robot, objective_with([]), ObstacleSet(), 0.055, margin=0.005)
    cmd = jog_commands([JogSegment(0.3, np.array([0.0, 0.06, 0.0, 0.0]))], DT)
    own = OwnQP(spec)
    pairs = [
        (own, QPResolver(spec, "daqp")),
        (OwnBaseline(spec), PseudoinverseResolver(spec, damping=0.01)),
    ]
    for mine, builtin in pairs:
        a, b = (run(robot, PIPE_RADIUS, r, q0, cmd, DT) for r in (mine, builtin))
        assert a.ok and a.n_steps == b.n_steps > 50
        np.testing.assert_array_equal(a.q, b.q)
    assert own.made == 1
