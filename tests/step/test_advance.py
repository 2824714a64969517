"""Verified steps (``dvqp.step.advance``): integrate, check every limit exactly, split a step
that breaks one, check the straight motion of a large or split step between its ends."""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp import (
    Objective,
    Obstacle,
    ObstacleSet,
    QPResolver,
    Robot,
    Stepper,
    StepSpec,
    ToolTask,
)
from dvqp.limits import AccelerationLimit, ObstacleDamper
from dvqp.resolution import make_resolver
from dvqp.run.planning import scene_commands
from dvqp.step import JOINT_STRIDE, MAX_HALVINGS, advance
from dvqp.step.engine import Resolution
from tests.common import PIPE_RADIUS, Q0
from tests.oracles.resolution import frames, link_distances, point_distances

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "paper-two-inlets.toml"
PERIOD = 2.0 * math.pi * PIPE_RADIUS


@functools.cache
def paper(dt: float) -> dvqp.Scene:
    text = SCENE.read_text(encoding="utf-8").replace("dt = 0.005", f"dt = {dt}")
    return dvqp.scenes.loads(text, f"paper-dt{dt}.toml")


def run(dt: float, backend: str = "daqp", **kw: object) -> dvqp.Trajectory:
    scene = paper(dt)
    resolver = make_resolver(backend, scene.spec())
    c = scene_commands(scene)
    return dvqp.simulate(
        scene.robot,
        scene.pipe_radius,
        resolver,
        scene.q0,
        c.velocity,
        scene.dt,
        obstacles=scene.obstacles,
        **kw,  # type: ignore[arg-type]
    )


def test_a_large_step_that_breaks_a_limit_is_split_and_then_keeps_it() -> None:
    traj = run(0.5)
    assert traj.ok and traj.substeps.max() > 1
    assert traj.limits_kept.all() and traj.limit_excess.max() <= 1e-4
    split = int(np.argmax(traj.substeps))
    # the step's joint velocity is the mean over its substeps
    np.testing.assert_allclose(traj.q[split + 1], traj.q[split] + 0.5 * traj.qdot[split])


def test_without_splitting_the_step_fails_and_names_the_limit() -> None:
    traj = run(0.5, max_halvings=0)
    failed = np.flatnonzero(~traj.success)
    assert failed.size > 0
    status = str(traj.status[failed[0]])
    assert status.startswith("failed: ") and " in 1 substeps" in status and "\n" not in status
    assert any(word in status for word in ("clearance", "height", "tilt", "joint position"))
    # a failed step holds the arm still, and every saved sample keeps every limit
    np.testing.assert_array_equal(traj.q[failed[0] + 1], traj.q[failed[0]])
    assert traj.limits_kept.all()


def test_the_baseline_is_measured_not_verified() -> None:
    traj = run(0.005, "pinv")
    assert traj.ok and (traj.substeps == 1).all()
    assert not traj.limits_kept.all() and traj.limit_excess.max() > 0.01


def test_advance_returns_the_state_it_reached() -> None:
    scene = paper(0.005)
    resolver = make_resolver("daqp", scene.spec())
    s = Stepper(scene.robot, scene.pipe_radius, resolver, scene.q0, 0.005, scene.obstacles)
    s.start(scene.q0)
    start = s.state.q.copy()
    jac, tool = np.array(s.state.tool_jacobian), s.state.tool.copy()
    moved = advance(s, np.array([0.05, 0, 0, 0]), 0.005)
    assert moved.substeps == 1 and moved.step.success and moved.excess == dvqp.limits.NO_EXCESS
    np.testing.assert_allclose(s.state.q, start + 0.005 * moved.step.qdot, rtol=0, atol=1e-15)
    # from rest, the joints may only reach q̈_max·dt: the task gives way, and says by how much
    assert moved.step.status == "relaxed" and 0 < moved.step.task_error < 0.05
    reached = jac @ moved.step.qdot
    assert moved.step.task_error == pytest.approx(abs(reached[0] - 0.05), rel=1e-9)
    assert s.state.tool[0] - tool[0] == pytest.approx(0.005 * reached[0], abs=1e-6)
    acceleration = next(x for x in resolver.spec.limits if isinstance(x, AccelerationLimit))
    np.testing.assert_array_equal(acceleration.previous, moved.step.qdot)  # it was told


# -- the straight motion between a step's ends ------------------------------------------------

Q_A = np.array(Q0)
Q_B = Q_A + 0.8 * np.eye(13)[0]  # the carriage turns: every part moves 0.2 m in l
DETOUR = 0.5 * (Q_A + Q_B) + 0.6 * np.eye(13)[1]
"""A configuration the straight motions from Q_A and to Q_B reach without touching the
obstacle in the way of the straight motion Q_A → Q_B."""


def in_the_way(robot: Robot) -> ObstacleSet:
    """A 1 cm circle 3 cm ahead of the tool, on the line it follows from Q_A to Q_B."""
    tool = frames(robot, Q_A, PIPE_RADIUS).tool[:2]
    return ObstacleSet([Obstacle(tool + np.array([0.03, 0.0]), 0.01)])


def clearance(robot: Robot, obstacles: ObstacleSet, q: np.ndarray) -> float:
    """Smallest clearance of the guarded parts at ``q`` (oracle: Pinocchio, brute force)."""
    f = frames(robot, q, PIPE_RADIUS)
    return float(
        min(
            point_distances(obstacles, f.guarded[:, :2], PERIOD).min(),
            link_distances(obstacles, f.guarded, PERIOD, f.k).min(),
        )
    )


def along(robot: Robot, obstacles: ObstacleSet, a: np.ndarray, b: np.ndarray) -> float:
    return min(clearance(robot, obstacles, a + t * (b - a)) for t in np.linspace(0, 1, 41))


class Scripted(Stepper):
    """A step whose QP answer is a script: the velocity from the loaded state to
    ``target(q, dt)`` over ``dt``; every configuration loaded is kept in :attr:`loaded`."""

    def __init__(self, robot: Robot, obstacles: ObstacleSet, target) -> None:  # type: ignore[no-untyped-def]
        damper = ObstacleDamper(obstacles, margin=0.0, influence=0.05)
        spec = StepSpec((ToolTask(),), Objective(), (damper,))
        super().__init__(robot, PIPE_RADIUS, QPResolver(spec, "daqp"), Q_A, 1.0, obstacles)
        self.target = target
        self.loaded: list[np.ndarray] = []
        self.start(Q_A)

    def load(self, q):  # type: ignore[no-untyped-def]
        self.loaded.append(np.array(q, dtype=float))
        return super().load(q)

    def resolve(self, command, dt):  # type: ignore[no-untyped-def]
        self.prepare(command, dt)
        q = self.state.q.copy()
        self.x[:] = (self.target(q, dt) - q) / dt
        return Resolution(True, "optimal", 1, 0.0, 0.0)


def test_the_straight_motion_of_a_large_step_is_checked_between_its_ends(robot: Robot) -> None:
    obstacles = in_the_way(robot)
    assert clearance(robot, obstacles, Q_A) > 0.01 and clearance(robot, obstacles, Q_B) > 0.01
    assert along(robot, obstacles, Q_A, Q_B) < -0.009  # the tool goes right through it
    unchecked = Scripted(robot, obstacles, lambda q, dt: q + dt * (Q_B - Q_A))
    moved = advance(unchecked, np.zeros(4), 1.0, verify=False)
    assert moved.step.success and moved.substeps == 1
    np.testing.assert_allclose(unchecked.state.q, Q_B, atol=1e-15)
    s = Scripted(robot, obstacles, lambda q, dt: q + dt * (Q_B - Q_A))  # the same velocity
    moved = advance(s, np.zeros(4), 1.0, max_halvings=0)
    status = moved.step.status
    assert not moved.step.success and np.all(moved.step.qdot == 0.0)
    assert status.startswith("failed: ") and status.endswith(" in 1 substeps")
    assert "/obstacles[0] clearance" in status and "straight motion" not in status
    assert moved.excess.quantity == "clearance" and moved.excess.value > 0.005
    np.testing.assert_array_equal(s.state.q, Q_A)  # the arm holds still
    # the points checked: on the segment, at most JOINT_STRIDE apart, ends excluded
    loaded, delta = np.unique(s.loaded, axis=0), Q_B - Q_A
    share = (loaded[:, 0] - Q_A[0]) / delta[0]
    np.testing.assert_allclose(loaded - Q_A - share[:, None] * delta, 0.0, atol=1e-15)
    interior = (share > 1e-12) & (share < 1.0 - 1e-12)
    inner, share = loaded[interior], share[interior]
    assert len(inner) == math.ceil(np.abs(delta).max() / JOINT_STRIDE) - 1 >= 39
    spacing = np.diff(np.concatenate([[0.0], np.sort(share), [1.0]])) * np.abs(delta).max()
    assert spacing.min() > 0.0 and spacing.max() <= JOINT_STRIDE + 1e-12
    # the excess reported is the one at the worst interior point, recomputed independently
    worst = min(inner, key=lambda q: clearance(robot, obstacles, q))
    assert moved.excess.actual == pytest.approx(clearance(robot, obstacles, worst), abs=2e-5)


def test_a_large_step_keeps_being_halved_until_it_fails(robot: Robot) -> None:
    s = Scripted(robot, in_the_way(robot), lambda q, dt: q + dt * (Q_B - Q_A))
    moved = advance(s, np.zeros(4), 1.0)
    assert not moved.step.success and moved.step.status.startswith("failed: ")
    assert moved.step.status.endswith(f" in {2**MAX_HALVINGS} substeps")
    assert moved.excess.broken and moved.excess.quantity == "clearance"
    np.testing.assert_array_equal(s.state.q, Q_A)


def test_a_split_step_is_also_checked_along_its_straight_motion(robot: Robot) -> None:
    """The arm executes the straight motion from the step's start to its end, whatever path
    the substeps took: a detour around an obstacle does not make the step safe."""
    obstacles = in_the_way(robot)
    assert min(along(robot, obstacles, Q_A, DETOUR), along(robot, obstacles, DETOUR, Q_B)) > 0.005

    def script(q: np.ndarray, dt: float) -> np.ndarray:
        if dt == 1.0:
            return Q_B  # the whole step: the interior check breaks it, so it is split
        return DETOUR if np.array_equal(q, Q_A) else Q_B

    s = Scripted(robot, obstacles, script)
    moved = advance(s, np.zeros(4), 1.0)
    assert not moved.step.success and moved.substeps == 2
    assert moved.step.status.startswith("failed: the straight motion: ")
    assert "/obstacles[0] clearance" in moved.step.status
    assert moved.step.status.endswith(" in 2 substeps")
    np.testing.assert_array_equal(s.state.q, Q_A)
    # with the obstacle only where the whole step would end, the split step is taken: its
    # velocity is the mean over the substeps
    beyond = Q_A + 2.0 * (Q_B - Q_A)
    far = ObstacleSet([Obstacle(frames(robot, beyond, PIPE_RADIUS).guarded[-1, :2], 0.01)])
    assert clearance(robot, far, beyond) < -0.009
    assert (
        min(
            along(robot, far, Q_A, DETOUR),
            along(robot, far, DETOUR, Q_B),
            along(robot, far, Q_A, Q_B),
        )
        > 0.005
    )
    free = Scripted(robot, far, lambda q, dt: beyond if dt == 1.0 else script(q, dt))
    moved = advance(free, np.zeros(4), 1.0)
    assert moved.step.success and moved.substeps == 2 and moved.step.status == "optimal"
    np.testing.assert_allclose(moved.step.qdot, Q_B - Q_A, atol=1e-12)
    np.testing.assert_allclose(free.state.q, Q_B, atol=1e-12)
