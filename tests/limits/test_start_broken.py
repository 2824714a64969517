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
from dvqp.kinematics import KinematicState
from dvqp.limits import ObstacleDamper, SurfaceHeight
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.run.comparison import summarize
from dvqp.scenes import loads
from dvqp.step import Stepper
from tests.oracles.limits import measure
from tests.runs import SCENES, run, scene

PAPER = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
# The body sits near h = 0.08 m and links 3 and 4 dip 8-9 mm lower between their points.
HIGH = PAPER.replace("min_height = 0.02", "min_height = 0.079")
BOUND, TOLERANCE = 0.079, 1e-4


def high_scene(tmp_path: Path) -> Path:
    assert HIGH != PAPER
    path = tmp_path / "high.toml"
    path.write_text(HIGH, encoding="utf-8")
    return path


def heights(*qs: np.ndarray) -> tuple[np.ndarray, tuple[str, ...]]:
    """The oracle: every body point's and link chord's lowest height over the configurations
    ``qs``, m (rows,), measured independently of the step, and the rows' labels."""
    paper = scene("paper-two-inlets")
    radius = paper.pipe_radius
    found = [
        measure(SurfaceHeight(BOUND), KinematicState.compute(paper.robot, q, radius)) for q in qs
    ]
    return np.min([m.value for m in found], axis=0), found[0].labels


def below(traj: Trajectory, bound: float = BOUND) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Each row's depth below the bound at the start and at its lowest sample, m, and labels."""
    start, labels = heights(traj.q[0])
    lowest, _ = heights(*traj.q)
    return bound - start, bound - lowest, labels


def expected_line(traj: Trajectory, bound: float = BOUND) -> str:
    start, worst, labels = below(traj, bound)
    broken = np.flatnonzero((start > 0) & (worst > TOLERANCE))
    i = int(broken[np.argmax(worst[broken])])
    more = f" and {len(broken) - 1} more" if len(broken) > 1 else ""
    worse = (worst - start)[broken].max()
    then = "never worse" if worse <= TOLERANCE else f"{worse * 1e3:.3g} mm worse than at the start"
    return (
        f"min_height: broken from the start by {worst[i] * 1e3:.3g} mm ({labels[i]}{more}), {then}"
    )


def test_a_floor_above_the_fixed_rail_point_is_refused_when_the_scene_loads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "rail.toml"
    path.write_text(PAPER.replace("min_height = 0.02", "min_height = 0.10"), encoding="utf-8")
    assert main(["plan", str(path), "-o", str(tmp_path / "rail.npz")]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"dvqp: {path}: constraints.min_height: 0.1 m is above the rail point (frame 'rail'), "
        "which the rail holds at h = 0.08 m: the carriage link rising from it can never be "
        "that high\n"
    )
    assert not (tmp_path / "rail.npz").exists()


def test_the_plan_summary_names_the_limit_with_its_true_amount_and_exits_1(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    path, out = high_scene(tmp_path), tmp_path / "high.npz"
    assert main(["plan", str(path), "-o", str(out)]) == 1
    captured = capsys.readouterr()
    traj = Trajectory.load(out)
    start, worst, labels = below(traj)
    assert 0.008 < worst.max() < 0.009 and (worst <= start + TOLERANCE).all()  # never worse
    assert labels[int(np.argmax(worst))] == "link4/height"
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
    start, worst, labels = below(traj)
    broken = np.flatnonzero((start > 0) & (worst > TOLERANCE))
    assert [b.label for b in found] == [labels[i] for i in broken]
    assert [b.label for b in found] == [
        "point4/height",
        "point5/height",
        "link3/height",
        "link4/height",
    ]
    assert {(b.limit, b.quantity, b.unit, b.bound, b.tolerance) for b in found} == {
        ("min_height", "height", "m", BOUND, TOLERANCE)
    }
    np.testing.assert_allclose([b.start for b in found], BOUND - start[broken], atol=1e-12)
    np.testing.assert_allclose([b.lowest for b in found], BOUND - worst[broken], atol=1e-12)
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
    assert main(["compare", str(path), "--backends", "daqp", "--json", str(out), "--check"]) == 1
    table = capsys.readouterr().out
    (row,) = json.loads(out.read_text(encoding="utf-8"))["results"]
    traj = plan(loads(HIGH, str(path)), "daqp")
    line = expected_line(traj)
    assert row["success"] is False and row["start_broken"] == line
    _, worst, labels = below(traj)
    assert row["max_limit_excess"] == pytest.approx(worst.max(), abs=1e-12)
    assert row["worst_limit"] == f"{labels[int(np.argmax(worst))]} height (m)"
    said = " ".join(table.split())  # the footer is wrapped to 100 columns
    assert f"daqp: starts outside its limits: {line}" in said and " NO " in table


def test_the_baseline_that_makes_it_worse_is_broken_and_says_by_how_much() -> None:
    upper = "center = [0.20, 0.48]\nradius = 0.07"  # moved over link 3, within its margin
    s = loads(PAPER.replace(upper, "center = [0.137, 0.44]\nradius = 0.063"), "margin.toml")
    traj = plan(s, "pinv")
    damper = next(x for x in s.limits if isinstance(x, ObstacleDamper))
    found = [measure(damper, KinematicState.compute(s.robot, q, s.pipe_radius)) for q in traj.q]
    safe, labels = found[0].safe, found[0].labels
    start, worst = safe - found[0].value, safe - np.min([m.value for m in found], axis=0)
    broken = np.flatnonzero((start > 0) & (worst > TOLERANCE))
    i, worse = int(broken[np.argmax(worst[broken])]), (worst - start)[broken].max()
    line = (
        f"margin: broken from the start by {worst[i] * 1e3:.3g} mm ({labels[i]} and "
        f"{len(broken) - 1} more), {worse * 1e3:.3g} mm worse than at the start"
    )
    assert worse > 0.005
    text = format_summary(s, traj, summarize(s, traj), None)
    value = text.split("\nlimits          ")[1].split("\nstep time")[0]
    limits = value.replace("\n" + " " * 18, " ").split("\n")  # a wrapped item on one line
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

    def lowest() -> np.ndarray:  # of every row the start put below the bound
        return np.array([b.lowest for b in s.start_broken()])

    start, _ = heights(q0)
    rows = start < BOUND - TOLERANCE

    def oracle(*qs: np.ndarray) -> np.ndarray:
        return heights(*qs)[0][rows]

    assert rows.sum() == 4
    np.testing.assert_allclose(lowest(), oracle(q0), rtol=0, atol=1e-12)
    s.record_at[0] = 1
    s.load(low)
    np.testing.assert_allclose(lowest(), oracle(q0, low), rtol=0, atol=1e-12)
    s.load(up)  # sample 1 again: the low state was rejected
    np.testing.assert_allclose(lowest(), oracle(q0, up), rtol=0, atol=1e-12)
    s.record_at[0] = 2
    s.load(low)
    np.testing.assert_allclose(lowest(), oracle(q0, up, low), rtol=0, atol=1e-12)
    s.start(q0)  # a new run forgets the old one's samples
    np.testing.assert_allclose(lowest(), oracle(q0), rtol=0, atol=1e-12)
