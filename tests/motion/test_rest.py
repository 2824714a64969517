"""Runs end at rest: after the last command every run brakes until each joint has stopped.

The braking steps are part of the trajectory, verified like every other; the last one is
exactly ``Q̇ = 0``. Checked here from the recorded joint velocities alone: the stop is no
faster than the acceleration limit allows and no slower than the bound derived for it, and an
independent backend agrees that 0 is the last step's answer.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest

import dvqp
import solvers
from dvqp import Bounds, Limit, Scene, Trajectory
from dvqp.cli.report import format_summary
from dvqp.errors import UnreachableTargetError
from dvqp.limits import AccelerationLimit, JointVelocityLimit
from dvqp.motion.stop import MARGIN, braking_steps, room
from dvqp.run.comparison import summarize
from dvqp.run.planning import check_run, scene_commands, scene_timing
from dvqp.scenes.scene import loads
from tests.runs import BUNDLED, LOOSE, LOOSE_ACCELERATION, QP, run, scene


def qdd_max(s: Scene) -> np.ndarray:
    return next(lim for lim in s.limits if isinstance(lim, AccelerationLimit)).qdd_max


def accelerations(traj: Trajectory) -> np.ndarray:
    """``(Q̇_k − Q̇_{k−1})/dt`` from the recorded velocities, the run starting at rest."""
    dt = traj.t[1] - traj.t[0]
    return np.diff(np.vstack([np.zeros((1, traj.q.shape[1])), traj.qdot]), axis=0) / dt


def assert_ends_at_rest(s: Scene, traj: Trajectory, tol: float = 1e-6) -> None:
    """At rest exactly, every acceleration within the limit, the stop as long as it must be
    (each step changes a joint's velocity by at most ``q̈_max dt``) and within its bound."""
    commanded = scene_commands(s).velocity.shape[0]
    if scene_timing(s) == "scaled":  # as many steps as following the path took
        assert traj.path_time[traj.brake_start] == pytest.approx(commanded * s.dt, abs=1e-12)
        commanded = traj.brake_start
    assert traj.brake_start == commanded and traj.n_steps > commanded
    assert not traj.qdot[-1].any() and traj.status[-1] == "optimal"
    a, dt = qdd_max(s), s.dt
    assert np.all(np.abs(accelerations(traj)) <= a + tol)
    last = traj.qdot[commanded - 1]
    steps = traj.n_steps - commanded
    assert steps >= math.ceil(float(np.max(np.abs(last) / (a * dt))) - 1e-9)
    weights = s.spec().diagonal(s.robot.n)
    ideal = math.sqrt(float(np.sum(weights * last**2))) / (math.sqrt(weights.min()) * a.min())
    assert steps <= math.ceil(ideal / dt) + 1 <= braking_steps(last, weights, a, dt)


@pytest.mark.parametrize("backend", QP)
@pytest.mark.parametrize("name", BUNDLED)
def test_every_bundled_scene_ends_at_rest_within_its_acceleration_limit(
    name: str, backend: str
) -> None:
    s, traj = scene(name), run(name, backend)
    check_run(s, traj)  # safe to send, the stop included
    if (name, backend) in LOOSE_ACCELERATION:
        assert_ends_at_rest(s, traj, tol=LOOSE * float(qdd_max(s).max()))
        pytest.xfail(LOOSE_ACCELERATION[name, backend])
    assert_ends_at_rest(s, traj)


@pytest.mark.parametrize("name", BUNDLED)
def test_the_baseline_stops_in_one_step_at_whatever_acceleration_that_takes(name: str) -> None:
    traj = run(name, "pinv")
    k = scene_commands(scene(name)).velocity.shape[0]
    assert traj.brake_start == k and traj.n_steps == k + 1
    assert not traj.qdot[-1].any() and traj.qdot[-2].any()
    np.testing.assert_array_equal(traj.qddot[-1], -traj.qdot[-2] / scene(name).dt)  # as it is


@functools.cache
def fast() -> Scene:
    """joint-limit following a path at 2 m/s, faster than its joints (1.5 rad/s) can: the run
    ends with the arm at speed and the tool behind its path."""
    s = scene("joint-limit")
    path = (
        "[motion.path]\nwaypoints = [[0.2973, 0.35, 0.08, 0.0], [0.3973, 0.45, 0.08, 0.0]]\n"
        "speed = 2.0\n"
    )
    return loads(s.text[: s.text.index("[[motion.jog]]")] + path)


@functools.cache
def fast_run(backend: str) -> Trajectory:
    return dvqp.plan(fast(), backend)


@pytest.mark.parametrize("backend", QP)
def test_a_stop_that_needs_a_joint_at_its_velocity_limit_holds_it_there(backend: str) -> None:
    """Holding the tool still from speed takes a joint to its velocity limit: the stop keeps
    it there (the acceleration limit alone would let it go faster) until the tool has
    stopped, then slows every joint at the acceleration limit."""
    s, traj = fast(), fast_run(backend)
    k, qd_max, step = traj.brake_start, s.robot.qd_max, qdd_max(s) * s.dt
    assert_ends_at_rest(s, traj)
    held = [
        i
        for i in range(k, traj.n_steps)
        if np.any(
            (np.abs(traj.qdot[i]) >= qd_max - 1e-9)
            & (np.abs(traj.qdot[i - 1]) + step > qd_max + 1e-9)
        )
    ]
    assert len(held) >= 5 and np.all(np.abs(traj.qdot) <= qd_max + 1e-9)
    assert set(traj.status[held]) == {"relaxed"}  # the tool gives way while the limit holds


def test_the_last_braking_step_is_the_qp_answer_of_its_problem_exactly() -> None:
    """0 is taken as the last step only where it is feasible; another backend asked the same
    problem finds 0 there too (to its tolerance), and where a joint was still faster than one
    step's acceleration the step could not be 0 and agrees with that backend's answer."""
    s, traj = fast(), fast_run("daqp")
    step = dvqp.Stepper(s.robot, s.pipe_radius, dvqp.QPResolver(s.spec(), "daqp"), s.q0, s.dt)
    step.start(s.q0)
    step.stopping = True
    fast_before = np.abs(traj.qdot[:-1]).max(axis=1) > qdd_max(s).min() * s.dt + 1e-3
    moving = int(np.flatnonzero(fast_before)[-1]) + 1  # the last step from such a speed
    assert traj.brake_start < moving < traj.n_steps - 1
    answers = []
    for i in (moving, traj.n_steps - 1):
        step.observe(traj.qdot[i - 1], s.dt)
        assert step.load(traj.q[i]) and step.prepare(np.zeros(4), s.dt) == -1
        p = step.problem()
        assert not p.q.any() and not p.b.any()  # λ = 0, the tool held still
        origin = bool(np.all(p.lb <= 0) and np.all(p.ub >= 0) and np.all(p.h >= 0))
        answers.append((origin, solvers.make_backend("clarabel").solve(p).x))
    (before, x_before), (last, x_last) = answers
    assert not before and np.abs(x_before - traj.qdot[moving]).max() < 1e-5
    # to its tolerance: an interior point keeps off a bound that lies at 0 (a run may end with
    # a joint's bound within 1e-15 of it, Clarabel's answer then 3.5e-6 inside it)
    assert last and np.abs(x_last).max() < 1e-5 and not traj.qdot[-1].any()


def test_a_stop_longer_than_the_room_reserved_grows_the_record() -> None:
    """Without a velocity limit nothing bounds the last speed in advance: the stop gets the
    room of a still arm, and the record grows when the stop needs more; every braking sample
    is still the state its step reached."""
    s = fast()
    spec = s.spec()
    free = dataclasses.replace(
        spec, limits=tuple(lim for lim in spec.limits if not isinstance(lim, JointVelocityLimit))
    )
    resolver, c = dvqp.QPResolver(free, "daqp"), scene_commands(s)
    traj = dvqp.simulate(
        s.robot,
        s.pipe_radius,
        resolver,
        s.q0,
        c.velocity,
        s.dt,
        obstacles=s.obstacles,
        reference=c.reference[:-1],
        feedback_gain=c.feedback_gain,
    )
    k = traj.brake_start
    assert traj.n_steps - k > room(s.robot, resolver, s.dt) == math.ceil(MARGIN / s.dt) + 1
    assert traj.ok and not traj.qdot[-1].any()
    assert np.all(np.abs(accelerations(traj)) <= qdd_max(s) + 1e-6)
    np.testing.assert_allclose(traj.q[k + 1 :], traj.q[k:-1] + s.dt * traj.qdot[k:], atol=1e-12)
    for i in range(k + 1, traj.n_steps + 1):  # written into the grown arrays, at their rows
        tool = dvqp.KinematicState.compute(s.robot, traj.q[i], s.pipe_radius).tool
        np.testing.assert_allclose(traj.tool[i], tool, atol=1e-12)


class KeepTurning(Limit):
    """The wrist's joint 13 must turn at 0.04 rad/s or more: a limit that forbids rest."""

    name = "keep_turning"

    def compute(self, state, dt):  # type: ignore[no-untyped-def]
        n = state.q.shape[0]
        low = np.full(n, -np.inf)
        low[-1] = 0.04
        return Bounds(low, np.full(n, np.inf))


def test_a_limit_that_forbids_rest_fails_the_run_naming_the_stop() -> None:
    s = loads(scene("joint-limit").text.replace("duration = 3.6", "duration = 0.1"))
    traj = dvqp.plan(s, "daqp", limits=[KeepTurning()])
    k = traj.brake_start
    bound = braking_steps(traj.qdot[k - 1], np.ones(s.robot.n), qdd_max(s), s.dt)
    assert traj.success[:-1].all() and traj.n_steps == k + bound + 1
    assert traj.status[-1] == (
        f"failed: could not stop within qdd_max in {bound * s.dt:.3g} s: joint13 still at "
        "0.04 rad/s"
    )
    assert not traj.qdot[-1].any() and np.array_equal(traj.q[-1], traj.q[-2])  # held still
    with pytest.raises(UnreachableTargetError, match="could not stop within qdd_max in"):
        check_run(s, traj)
    row = summarize(s, traj)
    assert not row["success"] and row["final_joint_speed"] == pytest.approx(0.04)
    assert "NOT at rest: final joint speed 0.04 rad/s" in format_summary(s, traj, row, None)


def test_the_bound_of_a_stop_is_twice_its_ideal_time_and_a_margin() -> None:
    weights, a = np.array([1.0, 4.0]), np.array([10.0, 5.0])
    qdot, dt = np.array([0.3, -0.4]), 0.01
    ideal = math.sqrt(0.3**2 + 4 * 0.4**2) / (1.0 * 5.0)  # ‖Q̇‖_W / (√w_min q̈_min), s
    assert braking_steps(qdot, weights, a, dt) == math.ceil((2 * ideal + MARGIN) / dt)
    assert braking_steps(qdot, weights, None, dt) == math.ceil(MARGIN / dt)  # no limit
    assert braking_steps(np.zeros(2), weights, a, 1.0) == 1


def test_without_stop_a_plan_ends_with_its_last_command_as_before() -> None:
    s = loads(scene("joint-limit").text.replace("duration = 3.6", "duration = 0.3"))
    stopped, moving = dvqp.plan(s, "daqp"), dvqp.plan(s, "daqp", stop=False)
    k = stopped.brake_start
    assert moving.n_steps == k and moving.brake_start == -1 and moving.braking_time is None
    assert moving.qdot[-1].any() and stopped.braking_time == pytest.approx(s.dt)  # one step
    for field in ("q", "qdot", "tool", "w", "min_clearance", "limit_excess"):
        expected = getattr(moving, field)
        np.testing.assert_array_equal(getattr(stopped, field)[: expected.shape[0]], expected)
    assert list(stopped.status[:k]) == list(moving.status)


@pytest.mark.parametrize("backend", ["pinv", "daqp"])
def test_a_qdd_max_too_small_to_stop_in_any_record_is_one_line_and_nothing_written(
    backend: str, tmp_path
) -> None:
    """Found by tests/scenes/test_fuzz.py: qdd_max = 1e-9 asked for a 554 GiB stop record."""
    from dvqp.cli import main

    text = scene("paper-two-inlets").text.replace("qdd_max = 10.0", "qdd_max = 1e-9")
    path = tmp_path / "tiny.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(dvqp.ParameterError, match=r"^qdd_max: 1e-09 rad/s\^2: a stop would take"):
        dvqp.plan(loads(text, str(path)), backend)
    assert main(["plan", str(path), "--backend", backend, "-o", str(tmp_path / "o.npz")]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.toml"]
    with pytest.raises(dvqp.ParameterError, match="at most 1e"):
        braking_steps(np.ones(3), np.ones(3), np.full(3, 1e-300), 0.005)
