"""Time-scaled path following: the probe slows along the path instead of leaving it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp.cli.main import main
from dvqp.errors import ParameterError, SceneError, UnreachableTargetError
from dvqp.motion.schedule import Schedule, path_deviation
from dvqp.resolution.qp import QPSolver, make_backend
from dvqp.run.planning import check_run, path_figures, scene_commands
from dvqp.scenes.scene import loads
from dvqp.workspace import QPBuffers
from tests.cli.test_cli import no_traceback

SCENES = Path(__file__).resolve().parents[2] / "scenes"
RUSH = SCENES / "weld-rush.toml"


def buffers(b: float) -> QPBuffers:
    """``min ½‖x‖²`` s.t. ``x₀ + x₁ = b``, ``|x| ≤ 1``: feasible for ``|b| ≤ 2``."""
    return QPBuffers(
        P=np.eye(2),
        cost=np.zeros(2),
        A=np.array([[1.0, 1.0]]),
        b=np.array([b]),
        G=np.zeros((0, 2)),
        h=np.zeros(0),
        lb=-np.ones(2),
        ub=np.ones(2),
    )


@pytest.mark.parametrize("backend", ["daqp", "osqp", "clarabel"])
def test_a_step_the_limits_cannot_take_at_full_speed_is_slowed_to_the_fastest_they_allow(
    backend: str,
) -> None:
    qp = buffers(3.0)  # feed-forward 2.5 plus feedback 0.5: only 2 fits, so σ = (2 − 0.5)/2.5
    solver = QPSolver(lambda: make_backend(backend), qp, task_weight=1e4)
    solver.feedforward[:] = 2.5
    answer = solver.solve()
    assert answer.status == "slowed"
    assert answer.rate == pytest.approx(0.6, abs=1e-5)
    np.testing.assert_allclose(answer.x, [1.0, 1.0], atol=1e-5)
    assert qp.b[0] == pytest.approx(0.5 + answer.rate * 2.5, abs=1e-12)  # the task it met


def test_the_time_scaled_problem_slows_a_step_the_strict_one_takes_at_full_speed() -> None:
    """Why a slowed streak still tries the strict problem first at each step: the time-scaled
    problem trades progress for the objective, so its answer is slower than nominal even where
    the limits allow full speed (here by ``b / (v (2ρ + 1))``: ``½(b − t v)²/2 + ½ρv²t²``
    least at that ``t = 1 − σ``). Taking it without the strict attempt would slow steps the
    strict task takes, and a streak would never end."""
    qp = buffers(1.5)  # feasible at full speed
    solver = QPSolver(lambda: make_backend("daqp"), qp, task_weight=1e4)
    solver.feedforward[:] = 1.0
    answer = solver.solve()
    assert (answer.status, answer.rate) == ("optimal", 1.0)
    qp.b[:] = 1.5
    solution, rate = solver._slow_down()
    assert solution.found
    assert rate == pytest.approx(1.0 - 1.5 / (2e4 + 1.0), abs=1e-9) and rate < 1.0


def test_a_step_that_cannot_hold_even_at_rest_on_the_path_relaxes_around_rest() -> None:
    qp = buffers(3.5)  # feedback alone (2.5) is past what the bounds allow
    solver = QPSolver(lambda: make_backend("daqp"), qp, task_weight=1e4)
    solver.feedforward[:] = 1.0
    answer = solver.solve()
    assert (answer.status, answer.rate) == ("relaxed", 0.0)
    assert qp.b[0] == pytest.approx(2.5)  # relaxed toward the path's point, not beyond it
    np.testing.assert_allclose(answer.x, [1.0, 1.0], atol=1e-6)


def test_without_a_feedforward_a_conflict_relaxes_as_before() -> None:
    qp = buffers(3.0)
    answer = QPSolver(lambda: make_backend("daqp"), qp, task_weight=1e4).solve()
    assert (answer.status, answer.rate) == ("relaxed", 1.0)
    assert qp.b[0] == 3.0


def test_the_schedule_interpolates_the_reference_and_commands_the_nominal_motion() -> None:
    rng = np.random.default_rng(3)
    reference = np.cumsum(rng.normal(size=(6, 4)), axis=0)
    dt = 0.1
    commands = np.diff(reference, axis=0) / dt
    schedule = Schedule(commands, reference[:-1], 2.0, dt, 10.0, scaled=True)
    here = reference[2] + 0.25 * (reference[3] - reference[2])
    xdot, feedforward, span = schedule.command(2.25, here)
    ahead = reference[3] + 0.25 * (reference[4] - reference[3])
    np.testing.assert_allclose(feedforward, (ahead - here) / dt)
    np.testing.assert_allclose(xdot, feedforward)  # on the path: no feedback
    _, last, span = schedule.command(4.5, reference[4])  # half a step from the end
    assert span == 0.5
    middle = reference[4] + 0.5 * (reference[5] - reference[4])
    np.testing.assert_allclose(last, (reference[5] - middle) / dt)
    assert schedule.done(5.0) and not schedule.done(4.99)


def test_path_deviation_is_the_distance_to_the_polyline_by_dense_sampling() -> None:
    rng = np.random.default_rng(7)
    reference = np.column_stack([np.cumsum(rng.normal(size=(12, 3)), axis=0), np.zeros(12)])
    tool = np.column_stack([rng.normal(size=(40, 3)) * 3.0, np.zeros(40)])
    t = np.linspace(0.0, 1.0, 4001)
    dense = np.concatenate(
        [
            a + t[:, None] * (b - a)
            for a, b in zip(reference[:-1, :3], reference[1:, :3], strict=True)
        ]
    )
    oracle = np.linalg.norm(tool[:, None, :3] - dense[None], axis=2).min(axis=1)
    found = path_deviation(reference, tool)
    assert np.all(found <= oracle + 1e-12)
    np.testing.assert_allclose(found, oracle, atol=2e-3)  # the sampling's own spacing


@pytest.fixture(scope="module")
def rush() -> dvqp.Scene:
    return dvqp.load_scene(RUSH)


@pytest.fixture(scope="module")
def rush_runs(rush: dvqp.Scene) -> dict[str, dvqp.Trajectory]:
    return {timing: dvqp.plan(rush, "daqp", timing=timing) for timing in ("fixed", "scaled")}


def test_scaled_timing_stays_on_the_weld_where_fixed_timing_leaves_it(
    rush: dvqp.Scene, rush_runs: dict[str, dvqp.Trajectory]
) -> None:
    fixed, scaled = rush_runs["fixed"], rush_runs["scaled"]
    reference = scene_commands(rush).reference
    relaxed = fixed.status == "relaxed"
    assert relaxed.sum() > 50  # today's mode gives way...
    assert path_deviation(reference, fixed.tool).max() > 0.01  # ...and leaves the weld
    with pytest.raises(UnreachableTargetError):
        check_run(rush, fixed)
    check_run(rush, scaled)  # every limit kept, the path's end reached
    assert np.sum(scaled.status == "slowed") > 50 and not np.any(scaled.status == "relaxed")
    assert path_deviation(reference, scaled.tool).max() <= 1e-3  # at every sample
    figures = path_figures(rush, scaled)
    assert figures["path_duration"] > figures["nominal_duration"] == pytest.approx(3.39)
    slowed = scaled.path_time[1:] - scaled.path_time[:-1] < 0.999 * rush.dt
    assert slowed[: scaled.brake_start].sum() >= np.sum(scaled.status == "slowed") - 1


def test_a_path_the_limits_never_bind_on_runs_identically_in_both_timings() -> None:
    scene = dvqp.load_scene(SCENES / "weld-circumference.toml")
    fixed, scaled = (dvqp.plan(scene, "daqp", timing=t) for t in ("fixed", "scaled"))
    np.testing.assert_array_equal(fixed.q, scaled.q)
    np.testing.assert_array_equal(fixed.path_time, scaled.path_time)
    # the reference interpolated at whole steps: equal but for rounding
    np.testing.assert_allclose(fixed.tracking_error, scaled.tracking_error, rtol=0, atol=1e-15)


def test_a_path_not_finished_is_reported_as_not_reached(
    rush: dvqp.Scene, rush_runs: dict[str, dvqp.Trajectory]
) -> None:
    scaled = rush_runs["scaled"]
    stalled = dataclasses.replace(scaled, path_time=scaled.path_time * 0.5)
    with pytest.raises(UnreachableTargetError, match="path was not finished: 50% of it"):
        check_run(rush, stalled)


def test_the_baseline_breaking_a_joint_velocity_limit_is_not_safe_to_send(rush: dvqp.Scene) -> None:
    traj = dvqp.plan(rush, "pinv")
    assert np.any(np.abs(traj.qdot) > rush.robot.qd_max)
    with pytest.raises(dvqp.LimitViolationError, match="joint velocity limit"):
        check_run(rush, traj)


def test_path_time_is_saved_and_loaded(
    rush_runs: dict[str, dvqp.Trajectory], tmp_path: Path
) -> None:
    traj = rush_runs["scaled"]
    again = dvqp.Trajectory.load(traj.save(tmp_path / "run.npz"))
    np.testing.assert_array_equal(again.path_time, traj.path_time)


def test_an_unknown_timing_in_a_scene_names_its_field() -> None:
    text = RUSH.read_text(encoding="utf-8").replace('timing = "scaled"', 'timing = "lazy"')
    with pytest.raises(SceneError, match=r"motion\.path\.timing: must be one of fixed, scaled"):
        loads(text, source="rush.toml")


def test_scaling_a_jog_scene_is_refused() -> None:
    scene = dvqp.load_scene(SCENES / "paper-two-inlets.toml")
    with pytest.raises(ParameterError, match="no path to slow along"):
        dvqp.plan(scene, "daqp", timing="scaled")


def test_plan_prints_both_durations_and_the_deviation(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", str(RUSH)]) == 0
    out = capsys.readouterr().out
    assert "slowed" in out and "(nominal 3.390 s)" in out and "worst deviation from it" in out
    assert main(["plan", str(RUSH), "--timing", "fixed"]) == 1
    captured = capsys.readouterr()
    assert "relaxed" in captured.out and "target not reached" in captured.err
    assert main(["plan", str(SCENES / "fold.toml"), "--timing", "scaled"]) == 2
    assert no_traceback(capsys.readouterr().err)
