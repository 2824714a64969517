"""The carriage link: from the rail point (where the carriage rides its rail) to body point 1,
guarded like every other link of the arm."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp import KinematicState, Robot
from dvqp.cli import main
from dvqp.cli.drawing import body_at
from dvqp.limits import ObstacleDamper
from tests.common import LINK_LENGTHS, PIPE_RADIUS, random_configurations
from tests.limit_fixtures import ROOT, damper_rows, scene
from tests.oracles.resolution import frames, point_distances

CLAMP = ROOT / "scenes" / "carriage-clamp.toml"


def test_the_rail_point_rides_the_rail_one_carriage_link_from_body_point_one(robot: Robot) -> None:
    """On the rail (radius L1, any carriage angle), at L2 from body point 1, and its height has
    no gradient: no joint moves it off the rail."""
    l1, l2 = LINK_LENGTHS[0], LINK_LENGTHS[1]
    for q in random_configurations(12, seed=91, spread=math.pi):
        f = frames(robot, q, PIPE_RADIUS)  # Pinocchio's frames, not dvqp's kinematics
        rail, point1 = f.origins[robot.n_points + 1], f.origins[0]
        assert math.hypot(rail[0], rail[1]) == pytest.approx(l1, abs=1e-12)
        assert rail[2] == pytest.approx(0.0, abs=1e-12)
        assert np.linalg.norm(point1 - rail) == pytest.approx(l2, abs=1e-12)
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        np.testing.assert_allclose(state.guarded[-1], f.guarded[-1], rtol=0, atol=1e-12)
        assert np.abs(state.guarded_jacobians[-1, 2]).max() < 1e-12


def true_clearance(traj: dvqp.Trajectory, s: dvqp.Scene, samples: int = 50) -> float:
    """The carriage link's smallest clearance over the run: the real straight 3-D segment,
    sampled, each sample mapped to the developed view (Pinocchio's frames)."""
    period, worst = 2 * math.pi * s.pipe_radius, math.inf
    t = np.linspace(0.0, 1.0, samples)[:, None]
    for q in traj.q:
        o = frames(s.robot, q, s.pipe_radius).origins
        p = o[-1] + t * (o[0] - o[-1])
        lz = np.column_stack([s.pipe_radius * np.arctan2(p[:, 1], p[:, 0]), p[:, 2]])
        worst = min(worst, float(point_distances(s.obstacles, lz, period).min()))
    return worst


def test_a_clamp_beside_the_rail_keeps_the_carriage_link_at_its_margin() -> None:
    s = dvqp.load_scene(CLAMP)
    traj = dvqp.plan(s, "daqp")
    assert traj.ok and traj.min_clearance.min() == pytest.approx(0.01, abs=1e-4)
    assert true_clearance(traj, s) >= 0.01 - 1e-4  # checked independently, on the real link
    baseline = dvqp.plan(s, "pinv")  # the paper's step holds no limit: through the clamp
    assert true_clearance(baseline, s) < -0.015 and baseline.min_clearance.min() < -0.015


def test_the_summary_names_the_carriage_link(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["plan", str(CLAMP), "--backend", "pinv"]) == 1
    out, err = capsys.readouterr()
    assert "(carriage/" in out and "carriage/" in err


def test_the_carriage_link_s_rows_are_minus_the_gradient_of_its_clearance() -> None:
    s = scene("carriage-clamp")
    limit = next(lim for lim in s.spec().limits if isinstance(lim, ObstacleDamper))
    stepper = dvqp.Stepper(
        s.robot, s.pipe_radius, dvqp.QPResolver(s.spec(), "daqp"), s.q0, s.dt, s.obstacles
    )
    stepper.start(s.q0)
    rows = damper_rows(stepper, limit, s.q0, fd=True)
    assert any(label.startswith("carriage/") for label in rows.labels)


def test_the_rail_point_is_recorded_and_the_carriage_link_drawn(tmp_path: Path) -> None:
    s = dvqp.load_scene(CLAMP)
    traj = dvqp.plan(s, "daqp")
    assert traj.rail.shape == (traj.t.shape[0], 3)
    for i in range(0, traj.t.shape[0], 50):  # Pinocchio's rail frame, in the developed view
        rail = frames(s.robot, traj.q[i], s.pipe_radius).guarded[-1]
        np.testing.assert_allclose(traj.rail[i], rail, rtol=0, atol=1e-12)
    body = body_at(traj, 10)  # the rail point first: the carriage link is drawn
    assert body.shape == (s.robot.n_points + 2, 3)
    assert math.dist(body[0, :2], traj.rail[10, :2]) < 1e-12
    saved = traj.save(tmp_path / "clamp.npz")
    np.testing.assert_array_equal(dvqp.Trajectory.load(saved).rail, traj.rail)
    with np.load(saved) as data:  # a file written before the rail was recorded: none drawn
        arrays = {k: data[k] for k in data.files if k != "rail"}
    np.savez(tmp_path / "old.npz", **arrays)
    old = dvqp.Trajectory.load(tmp_path / "old.npz")
    assert old.rail.shape[0] == 0 and body_at(old, 10).shape == (s.robot.n_points + 1, 3)
