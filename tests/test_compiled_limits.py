"""The compiled limits write the reference path's rows and boxes, in place, to 1e-12."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest

from dvqp import KinematicState, Obstacle, ObstacleSet, Robot, load_scene
from dvqp.compiled import Kernel, ProximityBuffers, StepPlan
from dvqp.errors import SingularConfigurationError
from dvqp.geometry.proximity import proximity
from dvqp.limits import (
    AccelerationLimit,
    JointPositionLimit,
    JointVelocityLimit,
    Limit,
    ObstacleDamper,
    ProbeHeight,
    SelfCollision,
    SurfaceHeight,
    TiltLimit,
    damper_rhs,
)
from dvqp.limits.damper_kernels import damper_value
from dvqp.limits.self_collision import link_pairs, pair_distances
from dvqp.resolution.qp import limit_rows
from tests.common import LINK_LENGTHS, PIPE_RADIUS, spec_with

ROOT = Path(__file__).resolve().parent.parent
SCENES = {"paper-two-inlets": 0.5, "pipe-rack": 0.5, "fold": 1.0}
"""Bundled scenes and the spread (rad) of random configurations that reach their margins."""
DTS = (0.001, 0.005, 0.02)


@functools.cache
def scene(name: str):  # type: ignore[no-untyped-def]
    return load_scene(ROOT / "scenes" / f"{name}.toml")


def run(kernel: Kernel) -> None:
    kernel.function(*kernel.args)


def states(
    robot: Robot, q0: np.ndarray, count: int, seed: int, spread: float, radius: float = PIPE_RADIUS
) -> list[KinematicState]:
    """Reference states at random configurations around ``q0`` (singular ones left out)."""
    rng = np.random.default_rng(seed)
    found = []
    for q in q0 + rng.uniform(-spread, spread, size=(count, robot.n)):
        try:
            found.append(KinematicState.compute(robot, q, radius))
        except SingularConfigurationError:
            continue
    return found


class Compiled:
    """A plan with the kernels and verifiers of ``limits`` bound; loads reference states.

    The proximity buffers are the shapes' kernels' where those exist, else allocated and
    registered here; unless ``reference`` is False, at every state they are overwritten with
    the reference proximity, so the limits are checked on their own (the shapes' kernels have
    their own tests).
    """

    def __init__(
        self, limits: Sequence[Limit], robot: Robot, radius: float, reference: bool = True
    ) -> None:
        self.plan = plan = StepPlan(robot.n, robot.n_points, radius)
        self.limits, self.reference = tuple(limits), reference
        self.sets = [o for o in (getattr(lim, "obstacles", None) for lim in limits) if o]
        for obstacles in self.sets if reference else ():
            if plan.proximity(obstacles) is None:
                buffers = ProximityBuffers.allocate(len(obstacles), plan.k)
                plan._proximity[id(obstacles)] = (obstacles, buffers)
        self.kernels = {lim: lim.kernel(plan) for lim in limits}  # type: ignore[attr-defined]
        self.verifiers = {
            lim: lim.verifier(plan)  # type: ignore[attr-defined]
            for lim in limits
            if hasattr(lim, "excess")
        }
        every = [*self.kernels.values(), *self.verifiers.values()]
        self.bound = [plan.bind(k) for k in self.kernels.values() if k is not None]
        self.checks = [plan.bind(k) for k in self.verifiers.values() if k is not None]
        if not every or all(k is None for k in every):
            plan.bind(Kernel(run, ()))  # allocate the stacked arrays anyway

    def load(self, state: KinematicState) -> None:
        plan = self.plan
        plan.state.load(state)
        for kernel in plan.geometry:
            run(kernel)
        for obstacles in self.sets if self.reference else ():
            plan._proximity[id(obstacles)][1].load(proximity(state, obstacles))

    def step(self, state: KinematicState, dt: float) -> tuple[np.ndarray, ...]:
        """``G, h, lb, ub`` of the compiled limits at ``state``."""
        plan = self.plan
        self.load(state)
        plan.dt[0] = dt
        plan.lb[:] = -np.inf
        plan.ub[:] = np.inf
        for kernel in self.bound:
            run(kernel)
        return plan.stacked["G"], plan.stacked["h"], plan.lb, plan.ub

    def values(self, state: KinematicState) -> np.ndarray:
        """The verification values at ``state``."""
        self.load(state)
        for kernel in self.checks:
            run(kernel)
        return self.plan.stacked["values"].copy()


def assert_rows(compiled: Compiled, state: KinematicState, dt: float) -> int:
    """The compiled rows and box equal ``limit_rows``; returns the active row count."""
    G, h, lb, ub = compiled.step(state, dt)
    rows, box = limit_rows(spec_with(np.zeros(state.n), limits=compiled.limits), state, dt)
    active = np.isfinite(h)
    assert np.all(G[~active] == 0.0) and np.all(h[~active] == np.inf)
    np.testing.assert_allclose(G[active], rows.G, rtol=0, atol=1e-12)
    np.testing.assert_allclose(h[active], rows.h, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(lb, box.lb)
    np.testing.assert_array_equal(ub, box.ub)
    return int(active.sum())


@pytest.mark.parametrize("name", SCENES)
def test_a_scene_s_limits_compile_to_its_rows_and_box(name: str) -> None:
    sc = scene(name)
    compiled = Compiled(sc.spec().limits, sc.robot, sc.pipe_radius)
    found = states(sc.robot, sc.q0, 12, seed=1, spread=SCENES[name], radius=sc.pipe_radius)
    assert len(found) >= 6
    active = [assert_rows(compiled, state, dt) for state in found for dt in DTS]
    assert min(active) < max(active) or not len(sc.obstacles)  # rows come and go in place


@pytest.mark.parametrize("name", SCENES)
def test_the_rows_from_the_shapes_own_kernels(name: str) -> None:
    """End to end: the obstacle dampers read what the shapes' kernels wrote."""
    sc = scene(name)
    plan = StepPlan(sc.robot.n, sc.robot.n_points, sc.pipe_radius)
    if plan.proximity(sc.obstacles) is None:
        pytest.skip("an obstacle shape has no compiled kernel yet")
    compiled = Compiled(sc.spec().limits, sc.robot, sc.pipe_radius, reference=False)
    for state in states(sc.robot, sc.q0, 6, seed=12, spread=SCENES[name], radius=sc.pipe_radius):
        assert_rows(compiled, state, 0.005)


def near_set(state: KinematicState) -> ObstacleSet:
    """Circles around and on the arm: one on point 2's centre (no normal), one 0.05 mm
    inside point 3's 2 cm margin, one holding point 4 inside, one over link 4's middle, one
    grazing the probe, one far."""
    p = state.guarded[:, :2]
    return ObstacleSet([
        Obstacle(p[1], 0.02),
        Obstacle(p[2] + np.array([0.0, 0.05 - 5e-5]), 0.03),
        Obstacle(p[3] + np.array([0.01, 0.0]), 0.03),
        Obstacle(0.5 * (p[3] + p[4]) + np.array([0.0, 0.035]), 0.03),
        Obstacle(p[-1] + np.array([0.0, 0.045]), 0.04),
        Obstacle(np.array([-0.5, -1.0]), 0.05),
    ])  # fmt: skip


def tight_limits(state: KinematicState, deceleration: float) -> tuple[Limit, ...]:
    """Every damper, tuned so that parts sit above, within and deep below their margins."""
    return (
        ObstacleDamper(near_set(state), 0.02, 0.15, 0.7, deceleration),
        SurfaceHeight(0.08, 0.3, deceleration),
        ProbeHeight(0.06, 0.5, deceleration),
        TiltLimit(1.2, 0.5, deceleration),
        SelfCollision(0.12, 0.2, 0.5, deceleration),
    )


@pytest.mark.parametrize("deceleration", [1.0, 0.05, math.inf])
def test_the_dampers_rows_inside_and_outside_their_margins(
    robot: Robot, state0: KinematicState, deceleration: float
) -> None:
    compiled = Compiled(tight_limits(state0, deceleration), robot, PIPE_RADIUS)
    found = [state0, *states(robot, state0.q, 10, seed=2, spread=0.15)]
    for state in found:
        for dt in DTS:
            assert_rows(compiled, state, dt)
    h = compiled.step(found[0], 0.005)[1]
    assert np.any(h == 0.0) and np.any(h < 0.0) and np.any(h > 0.0)  # deep, drift, room


def test_joint_boxes_with_finite_infinite_and_crossed_limits(robot: Robot, q0: np.ndarray) -> None:
    q_min, q_max = q0 - 0.1, q0 + 0.1
    q_min[0], q_max[3] = -np.inf, np.inf
    limited = Robot.ndt13(LINK_LENGTHS, q_min=q_min, q_max=q_max)
    acceleration = AccelerationLimit(limited, np.linspace(2.0, 12.0, 13))
    limits = (JointPositionLimit(limited), JointVelocityLimit(limited), acceleration)
    compiled = Compiled(limits, limited, PIPE_RADIUS)
    rng = np.random.default_rng(3)
    for state in states(limited, q0, 8, seed=4, spread=0.2):  # some joints past their limits
        for dt in DTS:
            assert_rows(compiled, state, dt)
            acceleration.observe(rng.uniform(-2.0, 2.0, 13), dt)
            assert_rows(compiled, state, dt)
    acceleration.reset()
    assert_rows(compiled, state, 0.005)


def test_the_acceleration_limit_keeps_one_live_previous_velocity(robot: Robot) -> None:
    limit = AccelerationLimit(robot)
    previous = limit.previous
    limit.observe(np.arange(13.0), 0.01)
    assert limit.previous is previous
    np.testing.assert_array_equal(previous, np.arange(13.0))
    limit.reset()
    assert limit.previous is previous and not previous.any()


def test_limits_that_add_nothing_have_no_kernel(robot: Robot) -> None:
    plan = StepPlan(robot.n, robot.n_points, PIPE_RADIUS)
    for limit in (TiltLimit(0.0), ObstacleDamper(ObstacleSet([]))):
        assert limit.kernel(plan) is None and limit.verifier(plan) is None
    assert not plan._sizes


def test_the_pair_buffers_are_the_reference_pairs(robot: Robot, state0: KinematicState) -> None:
    plan = StepPlan(robot.n, robot.n_points, PIPE_RADIUS)
    pairs = plan.self_pairs()
    assert plan.self_pairs() is pairs and len(plan.geometry) == 1
    i, j = link_pairs(state0.k)
    np.testing.assert_array_equal(pairs.i, i)
    np.testing.assert_array_equal(pairs.j, j)
    for state in [state0, *states(robot, state0.q, 5, seed=5, spread=0.6)]:
        plan.state.load(state)
        run(plan.geometry[0])
        expected = pair_distances(np.ascontiguousarray(state.origins), i, j)
        for got, want in zip(
            (pairs.distance, pairs.normal, pairs.s, pairs.t), expected, strict=True
        ):  # the same kernel, compiled in another caller: LLVM may round differently
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-15)


def test_the_scalar_damper_value_is_damper_rhs_bit_for_bit() -> None:
    rng = np.random.default_rng(6)
    safe, depth = 0.01, 1e-4
    d = np.concatenate([
        safe + rng.uniform(-0.05, 0.2, 500), safe + rng.uniform(-2e-4, 2e-4, 500),
        [safe, safe - depth, safe + depth, np.nextafter(safe - depth, 0.0), -1.0],
    ])  # fmt: skip
    for gain in (0.1, 0.5, 1.0):
        for dt in (1e-3, 0.005, 0.1):
            for decel in (math.inf, 1.0, 0.2, 1e-3):
                want = damper_rhs(d, safe, gain, dt, depth, decel)
                got = np.array([damper_value(x, safe, gain, dt, depth, decel) for x in d])
                np.testing.assert_array_equal(got, want)
