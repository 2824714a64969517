"""A limit the start already breaks is named, with its true amount, by every report; no report
says "every limit kept" while a sample is past a true bound. The run itself may only keep such
a limit no worse (the arm cannot leave it at once): that is checked, and reported, too."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from dvqp import DvqpError, Trajectory, plan
from dvqp.cli import main
from dvqp.cli.report import format_summary
from dvqp.comparison import summarize
from dvqp.kinematics import KinematicState
from dvqp.limits import SurfaceHeight
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.scenes import loads
from dvqp.step import Stepper
from tests.runs import SCENES, run, scene

PAPER = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
HIGH = PAPER.replace("min_height = 0.02", "min_height = 0.10")  # the body sits near h = 0.08
BOUND, TOLERANCE = 0.10, 1e-4


def high_scene(tmp_path: Path) -> Path:
    assert HIGH != PAPER
    path = tmp_path / "high.toml"
    path.write_text(HIGH, encoding="utf-8")
    return path


def below(traj: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """The oracle, from the trajectory's points alone: each body point's depth below the bound
    at the start and at its lowest sample, m (k,)."""
    h = traj.points[:, :, 2]
    return BOUND - h[0], BOUND - h.min(axis=0)


def expected_line(traj: Trajectory) -> str:
    start, worst = below(traj)
    i = int(np.argmax(worst))
    assert (worst > TOLERANCE).all()  # every body point: "and 4 more"
    more = f" and {len(worst) - 1} more"
    then = ("never worse" if (worst - start).max() <= TOLERANCE
            else f"{(worst - start).max() * 1e3:.3g} mm worse than at the start")  # fmt: skip
    by = f"{worst[i] * 1e3:.3g} mm"
    return f"min_height: broken from the start by {by} (point{i + 1}/height{more}), {then}"


def test_the_plan_summary_names_the_limit_with_its_true_amount_and_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    path, out = high_scene(tmp_path), tmp_path / "high.npz"
    assert main(["plan", str(path), "-o", str(out)]) == 1
    captured = capsys.readouterr()
    traj = Trajectory.load(out)
    start, worst = below(traj)
    assert 0.019 < worst.max() < 0.022 and (worst <= start + TOLERANCE).all()  # never worse
    line = expected_line(traj)
    assert "every limit kept" not in captured.out and "safe to send" not in captured.out
    assert "\nresult          NOT OK\n" in captured.out
    assert f"\nlimits          {line}\n" in captured.out
    assert captured.err == f"dvqp: {path}: daqp: starts outside its limits: {line}\n"


def test_the_trajectory_file_carries_each_value_broken_at_the_start(tmp_path: Path) -> None:
    pytest.importorskip("daqp")
    traj = plan(loads(HIGH, "high.toml"), "daqp")
    assert traj.ok and traj.limits_kept.all()  # kept no worse: every step made
    found = traj.start_broken
    assert [b.label for b in found] == [f"point{i}/height" for i in range(1, 6)]
    assert {(b.limit, b.quantity, b.unit, b.bound, b.tolerance) for b in found} == {
        ("min_height", "height", "m", BOUND, TOLERANCE)
    }
    h = traj.points[:, :, 2]
    np.testing.assert_array_equal([b.start for b in found], h[0])
    np.testing.assert_array_equal([b.lowest for b in found], h.min(axis=0))
    saved = traj.save(tmp_path / "high.npz")
    assert Trajectory.load(saved).start_broken == found
    with np.load(saved) as data:  # a file written before the field: loads, naming none
        arrays = {k: data[k] for k in data.files if k != "start_broken"}
    np.savez(tmp_path / "old.npz", **arrays)
    assert Trajectory.load(tmp_path / "old.npz").start_broken == ()
    np.savez(tmp_path / "bad.npz", **arrays, start_broken=np.str_('[{"x": 1}]'))
    with pytest.raises(DvqpError, match="not a dvqp trajectory"):
        Trajectory.load(tmp_path / "bad.npz")


def test_compare_names_it_in_its_table_and_json_with_the_true_excess(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    path, out = high_scene(tmp_path), tmp_path / "c.json"
    assert main(["compare", str(path), "--backends", "daqp", "--json", str(out)]) == 1
    table = capsys.readouterr().out
    (row,) = json.loads(out.read_text(encoding="utf-8"))["results"]
    traj = plan(loads(HIGH, str(path)), "daqp")
    line = expected_line(traj)
    assert row["success"] is False and row["start_broken"] == line
    assert row["max_limit_excess"] == pytest.approx(below(traj)[1].max(), abs=1e-15)
    assert row["worst_limit"] == f"point{np.argmax(below(traj)[1]) + 1}/height height (m)"
    assert f"daqp: starts outside its limits: {line}" in table and " NO " in table


def test_the_baseline_that_makes_it_worse_is_broken_and_says_by_how_much() -> None:
    s = loads(HIGH, "high.toml")
    traj = plan(s, "pinv")
    text = format_summary(s, traj, summarize(s, traj), None)
    line = expected_line(traj)
    assert "mm worse than at the start" in line
    limits = text.split("\nlimits          ")[1].split("\nstep time")[0].split("\n")
    assert limits[0].startswith("BROKEN: ") and limits[1] == f"                {line}"
    why = summarize(s, traj)["error"]  # the samples it made worse, and the start's
    assert " samples break a limit: " in why and why.endswith(
        f"; it starts outside its limits: {line}"
    )


def test_a_run_that_starts_within_every_bound_still_says_every_limit_kept() -> None:
    pytest.importorskip("daqp")
    s, traj = scene("paper-two-inlets"), run("paper-two-inlets", "daqp")
    assert traj.start_broken == ()
    text = format_summary(s, traj, summarize(s, traj), None)
    assert "\nresult          safe to send: every limit kept" in text
    assert "\nlimits          every limit kept to its tolerance (deepest: " in text


def test_a_start_within_an_obstacles_margin_is_named_by_its_pair() -> None:
    pytest.importorskip("daqp")
    upper = "center = [0.20, 0.48]\nradius = 0.07"  # moved over link 3, 3.3 mm from it
    s = loads(PAPER.replace(upper, "center = [0.137, 0.44]\nradius = 0.063"), "margin.toml")
    traj = plan(s, "daqp")
    row = summarize(s, traj)
    clearance = traj.min_clearance
    assert 0.0 < clearance[0] < 0.01 - TOLERANCE and clearance.min() >= clearance[0] - TOLERANCE
    assert row["success"] is False and row["start_broken"].startswith(
        f"margin: broken from the start by {(0.01 - clearance.min()) * 1e3:.3g} mm ("
    )
    assert "(link3/obstacles[0] and " in row["start_broken"]
    assert row["start_broken"].endswith(", never worse")


def test_a_sample_written_again_counts_only_its_last_state() -> None:
    """A step's first state may be rejected (split) and its sample written again: the lowest
    value of each verified quantity is over the samples as finally recorded."""
    paper = scene("paper-two-inlets")
    robot, q0 = paper.robot, paper.q0
    low, up = q0.copy(), q0.copy()
    low[3] -= 0.2  # point 5 well down
    up[3] += 0.02  # point 5 a little up
    resolver = PseudoinverseResolver(paper.spec().with_extra(limits=[SurfaceHeight(BOUND)]))
    record = TrajectoryRecorder(3, robot.n, robot.n_points)
    s = Stepper(robot, paper.pipe_radius, resolver, q0, paper.dt, None, record.arrays)
    s.record_at[0] = 0
    s.start(q0)

    def heights(*qs: np.ndarray) -> np.ndarray:
        states = [KinematicState.compute(robot, q, paper.pipe_radius) for q in qs]
        return np.min([state.points[:, 2] for state in states], axis=0)

    def lowest() -> np.ndarray:
        return np.array([b.lowest for b in s.start_broken()])

    np.testing.assert_array_equal(lowest(), heights(q0))
    s.record_at[0] = 1
    s.load(low)
    np.testing.assert_allclose(lowest(), heights(q0, low), rtol=0, atol=1e-15)
    s.load(up)  # sample 1 again: the low state was rejected
    np.testing.assert_allclose(lowest(), heights(q0, up), rtol=0, atol=1e-15)
    s.record_at[0] = 2
    s.load(low)
    np.testing.assert_allclose(lowest(), heights(q0, up, low), rtol=0, atol=1e-15)
    s.start(q0)  # a new run forgets the old one's samples
    np.testing.assert_array_equal(lowest(), heights(q0))
