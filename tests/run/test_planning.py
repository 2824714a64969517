"""Offline planning from scenes: backends, JOG and path references, failures, saving."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from dvqp import BackendError, KinematicState, Trajectory, plan
from dvqp.errors import UnreachableTargetError
from dvqp.motion.path import ToolPath
from dvqp.motion.simulate import dv_error
from dvqp.resolution.registry import available_resolvers, default_resolvers
from dvqp.run.planning import check_run, scene_commands
from dvqp.scenes.scene import Scene, loads
from tests.common import PIPE_RADIUS

SCENE = """
name = "small"
[pipe]
radius = 0.254
[robot]
model = "ndt13"
link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
q0 = [{q1}, -0.048, 0.068, 0.026, 0.08, 0.032, 0.088, -0.078, -0.088, 0.003, -0.434, 0.116, -0.278]
[objective]
orbital_level = 0.08
k_height = 100.0
[[obstacles]]
center = [0.20, 0.48]
radius = 0.07
weight = 20.0
[motion]
dt = {dt}
ramp = 0.0
{motion}
"""

JOG = """[[motion.jog]]
duration = 0.1
velocity = [0.05, 0.0, 0.0, 0.3]
[[motion.jog]]
duration = 0.05
velocity = [0.0, -0.04, 0.0, 0.0]"""


def scene(motion_: str = JOG, q1: float = 1.5708, dt: float = 0.005) -> Scene:
    return loads(SCENE.format(motion=motion_, q1=q1, dt=dt), "small.toml")


def path(waypoints: str, speed: float = 0.1, extra: str = "") -> str:
    return f"[motion.path]\nwaypoints = {waypoints}\nspeed = {speed}\n{extra}"


def test_backend_names_are_pinv_then_the_installed_qp_backends() -> None:
    names = available_resolvers()
    assert names[0] == "pinv" and len(names) == len(set(names))
    assert default_resolvers()[0] == "pinv"
    assert all(":" not in b for b in default_resolvers())
    assert set(default_resolvers()) <= set(names)


def test_an_unknown_backend_lists_the_installed_ones() -> None:
    with pytest.raises(BackendError) as info:
        plan(scene(), "no-such-solver")
    assert str(info.value).startswith("unknown backend 'no-such-solver'; installed: pinv, ")
    assert ", ".join(available_resolvers()) in str(info.value)


def test_jog_reference_is_the_start_plus_the_integrated_commands() -> None:
    s = scene()
    m = scene_commands(s)
    assert m.velocity.shape == (30, 4) and m.reference.shape == (31, 4)
    assert m.feedback_gain == 0.0
    start = KinematicState.compute(s.robot, s.q0, s.pipe_radius).tool
    np.testing.assert_allclose(m.reference[0], start)
    np.testing.assert_allclose(m.reference[-1] - start, [0.005, -0.002, 0.0, 0.03], atol=1e-12)


def test_a_jog_plan_tracks_its_commands_and_carries_the_scene() -> None:
    s = scene()
    traj = plan(s, "pinv")
    assert traj.ok and traj.backend == "pinv" and traj.scene_text == s.text
    assert traj.brake_start == 30 and traj.n_steps == 31  # the baseline stops in one step
    assert traj.tracking_error.shape == (32, 4)  # the stop against the motion's end, held
    assert np.abs(traj.tracking_error[:, :3]).max() < 2e-4  # Euler drift only
    check_run(s, traj)


def test_path_reference_moves_at_constant_speed_through_every_waypoint() -> None:
    wp = np.array([[0.30, 0.35, 0.08, 0.0], [0.40, 0.35, 0.08, 0.5], [0.40, 0.30, 0.08, 0.5]])
    start = np.array([0.30, 0.35, 0.08, 0.0])
    ref = ToolPath(wp, speed=0.1).reference(start, dt=0.01, radius=PIPE_RADIUS)
    assert ref.shape == (151, 4)  # 0.15 m at 0.1 m/s, 0.01 s steps
    step = np.linalg.norm(np.diff(ref[:, :3], axis=0), axis=1)
    np.testing.assert_allclose(step[step > 0], 1e-3, rtol=1e-9, atol=0.3e-3)
    assert np.sum(step < 1e-3 - 1e-9) <= 1  # only the step around the corner is shorter
    np.testing.assert_allclose(ref[0], start)
    np.testing.assert_allclose(ref[-1], wp[-1])
    np.testing.assert_allclose(ref[100], wp[1], atol=1e-12)  # α interpolated along the arc
    np.testing.assert_allclose(ref[50, 3], 0.25, atol=1e-12)


def test_path_reference_approaches_the_first_waypoint_from_the_start() -> None:
    wp = np.array([[0.32, 0.35, 0.08, 0.0], [0.42, 0.35, 0.08, 0.0]])
    start = np.array([0.30, 0.35, 0.08, 0.0])
    ref = ToolPath(wp, speed=0.1).reference(start, dt=0.01, radius=PIPE_RADIUS)
    assert ref.shape == (121, 4)  # 0.02 m approach + 0.10 m path at 0.1 m/s, 0.01 s steps
    np.testing.assert_allclose(ref[[0, 20, -1], 0], [0.30, 0.32, 0.42])


def test_waypoints_written_a_turn_away_are_shifted_by_whole_turns() -> None:
    turn = 2 * np.pi * PIPE_RADIUS
    wp = np.array([[0.30 + turn, 0.35, 0.08, 2 * np.pi], [0.40 + turn, 0.35, 0.08, 2 * np.pi]])
    start = np.array([0.30, 0.35, 0.08, 0.0])
    ref = ToolPath(wp, speed=0.1).reference(start, dt=0.01, radius=PIPE_RADIUS)
    assert ref.shape == (101, 4)  # no approach over a whole turn
    np.testing.assert_allclose(ref[-1], [0.40, 0.35, 0.08, 0.0], atol=1e-12)


def test_path_following_across_the_seam_keeps_the_tracking_error_bounded() -> None:
    # carriage turned so the tool starts at l = 0.75 m, just before the seam πR = 0.798 m
    s = scene(path("[[0.75, 0.35, 0.082, 0.0], [0.90, 0.35, 0.082, 0.2]]"), q1=3.35308, dt=0.01)
    backends = ["pinv"] + (["daqp"] if "daqp" in available_resolvers() else [])
    for backend in backends:
        traj = plan(s, backend)
        assert traj.ok, backend
        check_run(s, traj)
        assert traj.tool[0, 0] < math.pi * PIPE_RADIUS < traj.tool[-1, 0]  # crossed, unwrapped
        np.testing.assert_allclose(traj.tool[-1], [0.90, 0.35, 0.082, 0.2], atol=2e-4)
        assert np.abs(traj.tracking_error[:, :3]).max() < 5e-4
        assert np.abs(traj.tracking_error[:, 3]).max() < 5e-3
        wrapped = np.arctan2(
            np.sin(traj.tool[:, 0] / PIPE_RADIUS), np.cos(traj.tool[:, 0] / PIPE_RADIUS)
        )
        assert wrapped.min() < -3.0 and wrapped.max() > 3.0  # the raw l jumped by 2πR


def test_an_unreachable_path_is_returned_and_reported_as_a_failure() -> None:
    daqp = pytest.importorskip("daqp")
    assert daqp
    s = scene(path("[[0.30, 0.35, 0.082, 0.0], [0.30, 1.20, 0.082, 0.0]]", speed=0.4))
    traj = plan(s, "daqp")
    assert traj.ok  # every step kept the limits (the task was relaxed)
    with pytest.raises(UnreachableTargetError) as info:
        check_run(s, traj)
    why = info.value
    assert why.step == traj.n_steps and why.error is not None and why.error > 0.005
    message = str(why)
    assert message.startswith(f"small.toml: daqp: target not reached at t = {traj.t[-1]:.3f} s:")
    assert message.endswith("(tolerance 5 mm / 0.05 rad)") and "\n" not in message
    final = np.abs(dv_error(np.array([0.30, 1.20, 0.082, 0.0]), traj.tool[-1], PIPE_RADIUS))
    assert final[:3].max() == pytest.approx(why.error)


def test_failed_steps_are_reported_with_the_first_time() -> None:
    s = scene()
    traj = plan(s, "pinv")
    success = traj.success.copy()
    success[[7, 12]] = False
    status = traj.status.astype("<U40")
    status[7] = "failed: solver gave up"
    with pytest.raises(UnreachableTargetError) as info:
        check_run(s, dataclasses.replace(traj, success=success, status=status))
    why = info.value
    assert str(why) == (
        f"small.toml: pinv: 2 of 31 steps failed, first at t = {traj.t[7]:.3f} s "
        "(failed: solver gave up)"
    )
    assert why.step == 7


@pytest.mark.parametrize("suffix", [".npz", ".csv"])
def test_a_trajectory_round_trips_through_its_file(tmp_path: Path, suffix: str) -> None:
    s = scene(path("[[0.30, 0.35, 0.082, 0.0], [0.31, 0.36, 0.082, 0.1]]"))
    traj = plan(s, "pinv")
    out = traj.save(tmp_path / f"traj{suffix}")
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temporary file left
    if suffix == ".npz":
        back = Trajectory.load(out)
        for f in dataclasses.fields(Trajectory):
            a, b = getattr(traj, f.name), getattr(back, f.name)
            if isinstance(a, np.ndarray):
                np.testing.assert_array_equal(a, b, err_msg=f.name)
            else:
                assert a == b, f.name
        return
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    header = out.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert header[:2] == ["t", "q1"] and header[-5:] == ["alpha", "e_l", "e_z", "e_h", "e_alpha"]
    qdot = np.vstack([traj.qdot, np.zeros((1, traj.q.shape[1]))])  # 0 after the last sample
    expected = np.column_stack([traj.t, traj.q, qdot, traj.tool, traj.tracking_error])
    np.testing.assert_allclose(table, expected, rtol=1e-9, atol=1e-12)


def test_saving_to_an_unknown_format_writes_nothing(tmp_path: Path) -> None:
    traj = plan(scene(), "pinv")
    with pytest.raises(Exception, match="unknown format"):
        traj.save(tmp_path / "traj.txt")
    assert list(tmp_path.iterdir()) == []


def test_a_turn_in_place_takes_time_and_reaches_its_heading() -> None:
    wp = np.array([[0.30, 0.35, 0.08, 0.0], [0.35, 0.35, 0.08, 0.0], [0.35, 0.35, 0.08, 1.0]])
    start = wp[0].copy()
    ref = ToolPath(wp, speed=0.02).reference(start, dt=0.01, radius=PIPE_RADIUS)
    assert ref[-1, 3] == pytest.approx(1.0)
    turning = np.abs(np.diff(ref[:, 3])) > 0
    # 0.05 m of travel, then 1 rad counted as 0.1 m: 2.5 s + 5 s at 0.02 m/s, 0.01 s steps
    assert ref.shape[0] == 751 and turning.sum() in (500, 501)
    assert np.abs(np.diff(ref[:, 3])).max() <= 0.02 * 0.01 / 0.1 + 1e-12
