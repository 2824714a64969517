"""Offline integration of JOG commands, with and without position feedback."""

import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp import JogSegment, KinematicState, Obstacle, Robot, jog_commands, simulate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry import min_clearance
from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.motion.simulate import COMPILE_NOTICE, dv_error
from tests.common import PIPE_RADIUS, baseline, objective_with, obstacles_of

DT = 0.005


def test_jog_tracks_the_commanded_dv_velocity(robot: Robot, q0: np.ndarray) -> None:
    v = np.array([0.04, -0.02, 0.0, 0.1])
    cmd = jog_commands([JogSegment(0.5, v)], DT)
    traj = simulate(robot, PIPE_RADIUS, baseline(objective_with([])), q0, cmd, DT)
    assert traj.task_error.max() < 1e-10
    # Euler integration of the exact velocity: first-order drift only.
    np.testing.assert_allclose(traj.tool[-1] - traj.tool[0], 0.5 * v, atol=2e-3)
    assert np.all(np.isfinite(traj.q)) and traj.ok


def test_jog_pushes_body_points_out_of_an_obstacle_they_start_in(
    robot: Robot, q0: np.ndarray
) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    obstacle = Obstacle(state.points[2, :2] + np.array([0.0, 0.02]), 0.03, 20.0)
    objective = objective_with([obstacle])
    obstacles = obstacles_of(objective)
    assert min_clearance(state, obstacles) < 0
    cmd = jog_commands([JogSegment(2.0, np.array([0.02, 0.01, 0.0, 0.0]))], DT)
    traj = simulate(robot, PIPE_RADIUS, baseline(objective), q0, cmd, DT, obstacles=obstacles)
    point_clearance = (
        np.linalg.norm(traj.points[:, :, :2] - obstacle.center, axis=-1) - obstacle.radius
    )
    assert point_clearance[0].min() < -0.005, "point 3 starts inside"
    assert point_clearance[-1].min() > 0.005, "a body point is still inside the obstacle"
    assert traj.w[-1] > traj.w[0]
    assert traj.task_error.max() < 1e-9
    assert traj.min_clearance[0] < 0 < traj.min_clearance[-1]


def test_feedback_removes_a_reference_offset(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    target = state.tool + np.array([0.01, -0.01, 0.0, 0.05])
    n = 400
    traj = simulate(
        robot,
        PIPE_RADIUS,
        baseline(objective_with([])),
        q0,
        np.zeros((n, 4)),
        DT,
        reference=np.tile(target, (n, 1)),
        feedback_gain=5.0,
    )
    assert np.abs(dv_error(target, traj.tool[-1], PIPE_RADIUS)).max() < 1e-3


def test_dv_error_wraps_l_and_alpha() -> None:
    a = np.array([np.pi * PIPE_RADIUS - 0.01, 0.0, 0.0, np.pi - 0.01])
    b = np.array([-np.pi * PIPE_RADIUS + 0.01, 0.0, 0.0, -np.pi + 0.01])
    np.testing.assert_allclose(dv_error(a, b, PIPE_RADIUS), [-0.02, 0.0, 0.0, -0.02], atol=1e-12)


def test_dv_error_is_each_component_wrapped_alone_bit_for_bit() -> None:
    rng = np.random.default_rng(5)
    for shape in ((4,), (30, 4), (3, 5, 4)):
        a, b = 4.0 * rng.normal(size=shape), 4.0 * rng.normal(size=shape)
        expected = a - b
        expected[..., 0] = wrap(expected[..., 0], PIPE_RADIUS)
        expected[..., 3] = wrap_angle(expected[..., 3])
        np.testing.assert_array_equal(dv_error(a, b, PIPE_RADIUS), expected)


def test_bad_commands_raise_typed_errors(robot: Robot, q0: np.ndarray) -> None:
    resolver = baseline(objective_with([]))
    with pytest.raises(ShapeError, match="commands"):
        simulate(robot, PIPE_RADIUS, resolver, q0, np.zeros((5, 3)), DT)
    with pytest.raises(ParameterError, match="dt"):
        simulate(robot, PIPE_RADIUS, resolver, q0, np.zeros((5, 4)), 0.0)
    with pytest.raises(ShapeError, match="q0"):
        simulate(robot, PIPE_RADIUS, resolver, q0[:5], np.zeros((5, 4)), DT)
    with pytest.raises(ParameterError, match="commands"):
        simulate(robot, PIPE_RADIUS, resolver, q0, np.full((5, 4), np.nan), DT)
    with pytest.raises(ShapeError, match="reference"):
        simulate(robot, PIPE_RADIUS, resolver, q0, np.zeros((5, 4)), DT, reference=np.zeros(4))
    with pytest.raises(ParameterError, match="duration"):
        JogSegment(0.0, np.zeros(4))


def test_a_slow_compilation_is_announced_through_notice(monkeypatch: pytest.MonkeyPatch) -> None:
    module = sys.modules["dvqp.motion.simulate"]  # (dvqp.motion.simulate is the function)
    real = module.Stepper

    def slow(*args: object, **kwargs: object) -> object:
        time.sleep(0.3)
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(module, "Stepper", slow)
    monkeypatch.setattr(module, "COMPILE_NOTICE_SECONDS", 0.05)
    said: list[str] = []
    scene = dvqp.load_scene(Path(__file__).resolve().parents[2] / "scenes" / "fold.toml")
    traj = dvqp.plan(scene, "pinv", notice=said.append)
    assert said[0] == COMPILE_NOTICE and len(said) == 2
    assert re.fullmatch(r"compiled in \d+ s, cached", said[1])
    assert traj.ok and traj.n_steps > 0


def test_a_quick_start_says_nothing() -> None:
    said: list[str] = []
    scene = dvqp.load_scene(Path(__file__).resolve().parents[2] / "scenes" / "fold.toml")
    dvqp.plan(scene, "pinv")  # compiles the step if no run has yet
    dvqp.plan(scene, "pinv", notice=said.append)  # the compiled step is loaded, not compiled
    assert said == []
