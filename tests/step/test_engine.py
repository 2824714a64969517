"""The compiled step (the only one dvqp has) checked against independent computations.

Every bundled scene's run is re-verified sample by sample from its joint trajectory alone:
the integration, the frames and figures recorded (Pinocchio, brute-force distances, closest
points of our own), the task error (finite differences of Pinocchio's tool), the exact
verification, and every QP answer (eq. 18 where no inequality is active, otherwise a KKT
certificate of the problem the step wrote). Parts of your own run between the compiled stages,
on the same state; a subclass of one of dvqp's parts is one of your own.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

import dvqp
from dvqp import Bounds, Limit, ObjectiveTerm, QPResolver, Stepper, Term
from dvqp.geometry.bend import PRECISION
from dvqp.motion.simulate import dv_error
from dvqp.objective import OrbitalLevel
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.run.planning import scene_commands, scene_timing
from solvers import Problem
from tests import safety
from tests.oracles.resolution import (
    eq18,
    frames,
    kkt_residual,
    self_distances,
    tilt,
    verified_values,
    worst_excess,
    wrapped,
)
from tests.runs import BUNDLED, run, scene


def commands(s: dvqp.Scene, traj: dvqp.Trajectory) -> np.ndarray:
    """The tool command of every step, with the position feedback of a path, (N, 4): the
    braking steps at the end (from ``traj.brake_start``) hold the tool still (0). A
    time-scaled run's (:func:`scaled_commands`) as its steps wrote them."""
    if scene_timing(s) == "scaled":
        return scaled_commands(s, traj)[0]
    c = scene_commands(s)
    given = c.velocity.shape[0]
    assert traj.brake_start == given
    still = np.zeros((traj.n_steps - given, 4))
    if c.feedback_gain == 0.0:
        return np.vstack([c.velocity, still])
    error = dv_error(c.reference[:-1], traj.tool[:given], s.pipe_radius)
    return np.vstack([c.velocity + c.feedback_gain * error, still])


def scaled_commands(s: dvqp.Scene, traj: dvqp.Trajectory) -> tuple[np.ndarray, ...]:
    """A time-scaled run's steps from its recorded progress alone, each (N, 4) but ``σ`` (N,):
    the command each step wrote (nominal motion ``v`` from ``x_d(u)`` to ``x_d(u + 1)``, the
    path interpolated between its samples, plus the feedback), ``v``, and the rate ``σ`` the
    step made of it (the braking steps: 0, 0, 1)."""
    c = scene_commands(s)
    n, k = c.velocity.shape[0], traj.brake_start
    u = traj.path_time / s.dt
    span = np.minimum(1.0, n - u[:k])

    def at(v):
        return np.column_stack([np.interp(v, np.arange(n + 1), col) for col in c.reference.T])

    v = (at(u[:k] + span) - at(u[:k])) / s.dt
    xdot = v + c.feedback_gain * dv_error(at(u[:k]), traj.tool[:k], s.pipe_radius)
    rate = (u[1 : k + 1] - u[:k]) / span
    still = np.zeros((traj.n_steps - k, 4))
    return (
        np.vstack([xdot, still]),
        np.vstack([v, still]),
        np.concatenate([rate, np.ones(traj.n_steps - k)]),
    )


def slowed_residual(p: object, x: np.ndarray, v: np.ndarray, rate: float, rho: float) -> float:
    """The KKT residual of ``[x; σ]`` for the slowed step's own problem: the strict one ``p``
    with ``A Q̇ − σ v = b − v``, ``0 ≤ σ ≤ 1`` and ``½ ρ‖v‖²(1 − σ)²`` in the cost."""
    n, w = x.shape[0], rho * float(v @ v)
    P = np.zeros((n + 1, n + 1))
    P[:n, :n], P[n, n] = p.P, w  # type: ignore[attr-defined]
    G = None if p.G is None else np.column_stack([p.G, np.zeros(p.G.shape[0])])  # type: ignore[attr-defined]
    return kkt_residual(
        P,
        np.append(p.q, -w),
        np.column_stack([p.A, -v]),
        p.b - v,
        G,
        p.h,  # type: ignore[attr-defined]
        np.append(p.lb, 0.0),
        np.append(p.ub, 1.0),
        np.append(x, rate),
    )  # type: ignore[attr-defined]


def checked_samples(traj: dvqp.Trajectory) -> list[int]:
    """About 30 samples evenly spaced (at least 40 steps apart), the last, and the extremes of
    the recorded figures."""
    extremes = (
        np.argmin(traj.min_clearance),
        np.argmin(traj.self_distance),
        np.argmax(traj.limit_excess),
        np.argmin(traj.probe_clearance),
    )
    every = max(40, traj.n_steps // 30)
    return sorted({*range(0, traj.n_steps + 1, every), traj.n_steps, *map(int, extremes)})


@functools.cache
def start_values(name: str) -> list:  # type: ignore[type-arg]
    s = scene(name)
    return verified_values(s.spec().limits, s.robot, np.asarray(s.q0, float), s.pipe_radius)


@pytest.mark.parametrize("backend", ["pinv", "daqp"])
@pytest.mark.parametrize("name", BUNDLED)
def test_every_sample_of_a_run_is_the_state_its_joints_reach(name: str, backend: str) -> None:
    s, traj = scene(name), run(name, backend)
    R, period = s.pipe_radius, 2.0 * math.pi * s.pipe_radius
    scale = max(1.0, float(np.abs(traj.q).max()))
    np.testing.assert_allclose(
        traj.q[1:], traj.q[:-1] + s.dt * traj.qdot, rtol=0, atol=1e-13 * scale
    )
    for k in checked_samples(traj):
        f = frames(s.robot, traj.q[k], R)
        np.testing.assert_allclose(wrapped(traj.tool[k, 0] - f.tool[0], period), 0.0, atol=1e-12)
        np.testing.assert_allclose(traj.tool[k, 1:3], f.tool[1:3], rtol=0, atol=1e-12)
        assert wrapped(traj.tool[k, 3] - f.tool[3], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
        points = traj.points[k]
        np.testing.assert_allclose(
            wrapped(points[:, 0] - f.guarded[: f.k, 0], period), 0.0, atol=1e-12
        )
        np.testing.assert_allclose(points[:, 1:], f.guarded[: f.k, 1:], rtol=0, atol=1e-12)
        assert traj.tilt[k] == pytest.approx(tilt(f), abs=1e-9)
        true = self_distances(f.origins, f.k).min()
        assert traj.self_distance[k] == pytest.approx(true, abs=1e-12)
        if len(s.obstacles):
            whole, probe = safety.clearances(s, traj.q[k])  # the real links, sampled
            for reported, true in (
                (traj.min_clearance[k], whole),
                (traj.probe_clearance[k], probe),
            ):
                assert true - PRECISION - 1e-9 <= reported <= true + 1e-9  # never above the truth
        else:
            assert traj.min_clearance[k] == math.inf == traj.probe_clearance[k]
        now = verified_values(s.spec().limits, s.robot, traj.q[k], R)
        value, ratio, _ = worst_excess(start_values(name), now)
        # to solids, the oracle's links are the true ones, sampled (dvqp's at most PRECISION
        # below them where they matter): else the same rule to 1e-7
        close = PRECISION + 1e-7 if any(o.bounded for o in s.obstacles) else 1e-7
        assert traj.limit_excess[k] == pytest.approx(max(value, 0.0), abs=close)
        if abs(ratio - 1.0) > 1e-2:
            assert traj.limits_kept[k] == (ratio <= 1.0)


@pytest.mark.parametrize("backend", ["pinv", "daqp"])
@pytest.mark.parametrize("name", BUNDLED)
def test_the_task_error_of_every_step_is_measured_on_the_motion(name: str, backend: str) -> None:
    """``‖J̄ Q̇ − ẋ‖∞`` with ``J̄ Q̇`` the derivative of Pinocchio's tool along ``Q̇``."""
    s, traj = scene(name), run(name, backend)
    if not all(task.follows for task in s.spec().tasks):
        pytest.skip("a posture's or a frame's rows count in the task error; the tool's alone here")
    xdot, eps = commands(s, traj), 1e-6
    if scene_timing(s) == "scaled":  # a slowed step meets its task at the rate it made
        full, v, rate = scaled_commands(s, traj)
        xdot = full - (1.0 - rate)[:, None] * v
    taken = np.flatnonzero(traj.success & (traj.substeps == 1))
    assert taken.size > 0.9 * traj.n_steps
    for k in taken:
        ahead = frames(s.robot, traj.q[k] + eps * traj.qdot[k], s.pipe_radius).tool
        behind = frames(s.robot, traj.q[k] - eps * traj.qdot[k], s.pipe_radius).tool
        moved = (ahead - behind) / (2 * eps)
        assert traj.task_error[k] == pytest.approx(np.abs(moved - xdot[k]).max(), abs=1e-7)
    assert np.all(np.isinf(traj.task_error[~traj.success]))


@pytest.mark.parametrize("name", BUNDLED)
def test_every_answer_of_the_qp_is_optimal_for_the_problem_of_its_step(name: str) -> None:
    """At each step's state: the problem the step writes, and its answer certified: eq. 18
    where no inequality is active, else the KKT conditions (strict, or relaxed with the task
    weight ρ); braking is the velocity closest to rest in the box. The stop at the end has no
    objective (λ = 0) and holds the tool still, its last step exactly at rest."""
    s, traj = scene(name), run(name, "daqp")
    spec = s.spec()
    if not all(task.follows for task in spec.tasks):  # tests/run/test_priorities_in_use.py
        pytest.skip("the certificate here is of the tool's tasks; a posture's level is nested")
    step = Stepper(s.robot, s.pipe_radius, QPResolver(spec, "daqp"), s.q0, s.dt)
    step.start(s.q0)
    xdot, weights = commands(s, traj), spec.diagonal(s.robot.n)
    order = np.concatenate([task.index for task in spec.tasks])  # the tool tasks' rows of J̄
    breaks = step.layout.tasks.levels  # the levels' first rows (priority order)
    free = slowed = 0
    scaled = scene_timing(s) == "scaled"
    if scaled:
        _, speeds, rates = scaled_commands(s, traj)
    for k in np.flatnonzero(traj.success & (traj.substeps == 1)):
        step.observe(traj.qdot[k - 1] if k else np.zeros(s.robot.n), s.dt)  # the velocity so far
        step.stopping = k >= traj.brake_start
        assert step.load(traj.q[k]) and step.prepare(xdot[k], s.dt) == -1
        p, x, status = step.problem(), traj.qdot[k], traj.status[k]
        g = (0.0 if step.stopping else spec.objective.gain) * step.objective.gradient
        np.testing.assert_allclose(p.b, xdot[k][order], rtol=0, atol=1e-12)
        np.testing.assert_array_equal(p.q, -g)
        np.testing.assert_array_equal(p.P, np.diag(weights))
        assert np.all(p.lb - 1e-9 <= x) and np.all(x <= p.ub + 1e-9), k
        if status == "braking":  # the rows conflict: the box only (the verification decides)
            np.testing.assert_array_equal(x, np.clip(0.0, p.lb, p.ub))
            continue
        assert p.G is None or np.all(p.G @ x <= p.h + 1e-9), k
        if status == "slowed":  # optimal for its own problem, the strict one had no answer
            slowed += 1
            assert 0.0 <= rates[k] < 1.0
            assert slowed_residual(p, x, speeds[k], rates[k], spec.task_weight) < 1e-9, k
            continue
        if status == "relaxed" and breaks.shape[0] > 2:  # the lowest level gave way
            assert (
                lowest_level_residual(p, x, breaks, spec.task_weight * step.layout.row_weights)
                < 1e-9
            ), k
            continue
        relaxed = spec.task_weight if status == "relaxed" else None
        if relaxed is None:
            np.testing.assert_allclose(p.A @ x, p.b, rtol=0, atol=1e-9)
        residual = kkt_residual(p.P, p.q, p.A, p.b, p.G, p.h, p.lb, p.ub, x, relaxed)
        assert residual < 1e-9, (k, status, residual)
        slack = np.concatenate([x - p.lb, p.ub - x, [] if p.G is None else p.h - p.G @ x])
        if relaxed is None and slack.min() > 1e-7:
            free += 1
            expected = eq18(p.A, p.b, g, weights)
            np.testing.assert_allclose(x, expected, rtol=0, atol=1e-9 * max(1.0, np.abs(x).max()))
    assert free > 0  # eq. 18 was met as well as the active rows
    assert (slowed > 0) == scaled  # the time-scaled scene slows somewhere
    assert not traj.qdot[-1].any() and traj.status[-1] == "optimal"  # at rest, exactly


def lowest_level_residual(p: Problem, x: np.ndarray, breaks: np.ndarray, rho: np.ndarray) -> float:
    """The KKT residual of ``x`` for the lowest level's relaxed QP: the cost plus
    ``½ Σ ρ_i (A_i x − b_i)²`` over its rows, every level above held at what ``x`` achieves."""
    above, last = slice(0, breaks[-2]), slice(breaks[-2], breaks[-1])
    A, b, w = p.A[last], p.b[last], rho[last]
    P, q = p.P + A.T @ (w[:, None] * A), p.q - A.T @ (w * b)
    held = p.A[above]
    return kkt_residual(P, q, held, held @ x, p.G, p.h, p.lb, p.ub, x)


@pytest.mark.parametrize(
    ("name", "spread"), [("pipe-rack", 0.3), ("fold", 0.8), ("paper-two-inlets", 0.3)]
)
def test_the_worst_excess_of_a_state_is_recomputed_independently(name: str, spread: float) -> None:
    s = scene(name)
    spec = s.spec()
    step = Stepper(s.robot, s.pipe_radius, PseudoinverseResolver(spec), s.q0, s.dt)
    step.start(s.q0)
    rng = np.random.default_rng(5)
    broken = 0
    for q in np.asarray(s.q0) + rng.uniform(-spread, spread, size=(30, s.robot.n)):
        assert step.load(q)
        value, ratio, quantity = worst_excess(
            start_values(name), verified_values(spec.limits, s.robot, q, s.pipe_radius)
        )
        assert step.excess_now[0] == pytest.approx(value, abs=1e-7)
        assert step.broken == (ratio > 1.0)
        found = step.excess()
        assert found.value == step.excess_now[0] and found.quantity == quantity
        broken += step.broken
    assert broken >= 5


class _PlainLimit(Limit):
    """A user's limit with no kernel: a box wider than the scene's velocity limits."""

    name = "plain"

    def compute(self, state, dt):  # type: ignore[no-untyped-def]
        return Bounds(np.full(state.n, -10.0), np.full(state.n, 10.0))


class _Nothing(ObjectiveTerm):
    """A user's objective term that adds nothing."""

    def evaluate(self, state):  # type: ignore[no-untyped-def]
        return Term(0.0, np.zeros(state.n))


def test_parts_of_your_own_run_on_the_same_state_between_the_compiled_stages() -> None:
    s = scene("paper-two-inlets")
    assert np.all(s.robot.qd_max <= 10.0)
    spec = s.spec()
    objective = dvqp.Objective((*spec.objective.terms, _Nothing()), gain=spec.objective.gain)
    ours = dvqp.StepSpec(
        spec.tasks, objective, (*spec.limits, _PlainLimit()), spec.weights, spec.task_weight
    )
    c = scene_commands(s)
    traj = dvqp.simulate(
        s.robot,
        s.pipe_radius,
        QPResolver(ours, "daqp"),
        s.q0,
        c.velocity,
        s.dt,
        obstacles=s.obstacles,
    )
    plain = run("paper-two-inlets", "daqp")
    for field in ("q", "qdot", "w", "limit_excess", "min_clearance", "task_error"):
        np.testing.assert_array_equal(getattr(traj, field), getattr(plain, field), err_msg=field)
    np.testing.assert_array_equal(traj.status, plain.status)


class _Level(OrbitalLevel):
    """Changes the math of a built-in term: the inherited compiled kernel must not run."""

    def evaluate(self, state):  # type: ignore[no-untyped-def]
        return Term(1.0, np.arange(state.n, dtype=float))


class _Unchanged(dvqp.limits.SelfCollision):
    """Derives from a built-in limit and implements nothing of its own."""


def test_a_subclass_that_changes_a_built_ins_math_is_a_part_of_your_own(
    robot: dvqp.Robot, q0: np.ndarray
) -> None:
    spec = dvqp.StepSpec((dvqp.ToolTask(),), dvqp.Objective((_Level(0.08),)))
    step = Stepper(robot, 0.254, PseudoinverseResolver(spec), q0, 0.005)
    step.start(q0)
    assert step.objective.value == 1.0
    np.testing.assert_array_equal(step.objective.gradient, np.arange(13.0))


def test_a_plain_subclass_of_a_built_in_limit_keeps_its_compiled_rows(
    robot: dvqp.Robot, q0: np.ndarray
) -> None:
    steps = [
        Stepper(
            robot,
            0.254,
            QPResolver(dvqp.StepSpec((dvqp.ToolTask(),), limits=(limit,)), "daqp"),
            q0,
            0.005,
        )
        for limit in (dvqp.limits.SelfCollision(), _Unchanged())
    ]
    for step in steps:
        step.start(q0)
    assert not steps[1].layout.hooks.active
    np.testing.assert_array_equal(
        steps[0].arrays.dampers.distance, steps[1].arrays.dampers.distance
    )
    np.testing.assert_array_equal(
        steps[0].arrays.dampers.gradient, steps[1].arrays.dampers.gradient
    )
