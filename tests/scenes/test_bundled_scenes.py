"""Each bundled scene shows what ``scenes/README.md`` says it shows.

The QP claims run on DAQP (the fastest backend here); the baseline claims on ``pinv``.
"""

from __future__ import annotations

import dataclasses
from collections import Counter

import numpy as np
import pytest

from dvqp import Constraint, KinematicState, QPResolver, Scene, Stepper, Trajectory, plan
from dvqp.limits import ObstacleDamper, SurfaceHeight
from dvqp.run.planning import check_run, scene_commands
from dvqp.scenes.scene import loads
from tests.oracles.limits import measure
from tests.runs import QP, run, scene


def tight_rows(s: Scene, traj: Trajectory, tol: float = 1e-6) -> Counter[str]:
    """How many steps each QP inequality row (obstacle damper, height) held with equality.

    The rows are written again at every sample by a step of the scene's own (``Stepper.rows``);
    also checks that no row was broken by more than ``tol`` (m/s).
    """
    spec = s.spec()
    step = Stepper(s.robot, s.pipe_radius, QPResolver(spec, "daqp"), s.q0, s.dt)
    step.start(s.q0)
    limits = [lim for lim in spec.limits if isinstance(lim, (ObstacleDamper, SurfaceHeight))]
    commands = scene_commands(s).velocity
    tight: Counter[str] = Counter()
    for k in range(traj.n_steps):
        assert step.load(traj.q[k])
        step.stopping = k >= traj.brake_start  # the stop at the end: the tool held still
        step.prepare(commands[k] if k < traj.brake_start else np.zeros(4), s.dt)
        for limit in limits:
            rows = step.rows(limit)
            assert isinstance(rows, Constraint)
            slack = rows.h - rows.G @ traj.qdot[k]
            assert slack.min(initial=0.0) > -tol, f"step {k} breaks a row"
            tight.update(
                label for label, value in zip(rows.labels, slack, strict=True) if value < tol
            )
    return tight


def damper(s: Scene) -> ObstacleDamper:
    return next(limit for limit in s.limits if isinstance(limit, ObstacleDamper))


def height(s: Scene) -> SurfaceHeight:
    return next(limit for limit in s.limits if isinstance(limit, SurfaceHeight))


def exact_where_optimal(traj: Trajectory) -> bool:
    """The task is met exactly on every optimal step; the few steps where a limit engaged
    faster than the joints may accelerate (``relaxed``) give up at most 5 mm/s of it."""
    optimal = traj.status == "optimal"
    relaxed = traj.status == "relaxed"
    return bool(
        traj.task_error[optimal].max() < 1e-9
        and (not relaxed.any() or traj.task_error[relaxed].max() < 5e-3)
        and relaxed.sum() <= 0.02 * traj.n_steps
    )


def body_heights(traj: Trajectory) -> np.ndarray:
    return traj.points[:, :, 2]


def lowest_body(s: Scene, traj: Trajectory) -> float:
    """The lowest height (m) of any body point or link chord over the run, by the oracle."""
    states = (KinematicState.compute(s.robot, q, s.pipe_radius) for q in traj.q)
    return float(min(measure(height(s), state).value.min() for state in states))


def test_paper_scene_hovers_at_the_orbital_level_and_keeps_out_of_the_inlets() -> None:
    s, qp, base = (
        scene("paper-two-inlets"),
        run("paper-two-inlets", "daqp"),
        run("paper-two-inlets", "pinv"),
    )
    level, margin = s.orbital_level, damper(s).margin
    m = scene_commands(s)
    assert {len(s.jog), len(s.obstacles)} == {4, 2}
    assert np.count_nonzero(m.velocity[:, [0, 1, 3]].any(axis=0)) == 3  # JOG in l, z and α
    for traj in (qp, base):
        assert traj.ok and exact_where_optimal(traj)  # the probe follows the JOG
        np.testing.assert_allclose(traj.tool[-1], m.reference[-1], atol=5e-4)
        assert np.abs(body_heights(traj) - level).max() < 0.012  # hovering at h*
    assert margin - 1e-4 < qp.min_clearance.min() < margin + 1e-4  # held at the margin
    assert base.min_clearance.min() < -0.002  # the soft baseline enters an inlet
    # without the orbital term the body drifts off h* further
    flat = plan(loads(s.text.replace("k_height = 100.0", "k_height = 0.0")), "pinv")
    drift = np.abs(body_heights(flat) - level).max()
    assert drift > 1.5 * np.abs(body_heights(base) - level).max()


def test_circumference_scene_goes_once_round_across_the_seam() -> None:
    s, traj = scene("weld-circumference"), run("weld-circumference", "pinv")
    turn = 2 * np.pi * s.pipe_radius
    assert s.path is not None and s.path.waypoints[-1, 0] > np.pi * s.pipe_radius
    assert traj.ok
    check_run(s, traj)
    start = s.path.waypoints[0, 0]
    assert traj.tool[0, 0] < np.pi * s.pipe_radius < traj.tool[-1, 0]  # crossed the seam
    np.testing.assert_allclose(traj.tool[-1, 0], start + turn, atol=1e-3)  # once round
    assert np.abs(traj.tracking_error[:, :3]).max() < 5e-5
    assert np.abs(traj.tool[:, 1] - 0.35).max() < 5e-5  # on the weld all the way


def test_narrow_passage_makes_the_qp_rows_active_which_the_baseline_breaks() -> None:
    s, qp, base = (
        scene("narrow-passage"),
        run("narrow-passage", "daqp"),
        run("narrow-passage", "pinv"),
    )
    margin, h_min = damper(s).margin, height(s).min_height
    assert qp.ok and exact_where_optimal(qp)
    assert margin - 1e-4 < qp.min_clearance.min() < margin + 1e-4
    # the floor is held by the lowest part, a link chord (the points stay above it)
    assert h_min - 1e-4 < lowest_body(s, qp) < h_min + 1e-4 < body_heights(qp).min()
    tight = tight_rows(s, qp)
    assert sum(n for label, n in tight.items() if "/obstacles[" in label) > 50
    assert sum(n for label, n in tight.items() if label.endswith("/height")) > 50
    assert base.min_clearance.min() < -0.02  # through an inlet
    assert lowest_body(s, base) < body_heights(base).min() < h_min - 0.005  # below the floor


def test_joint_limit_scene_stops_the_carriage_at_its_limit() -> None:
    s, qp, base = scene("joint-limit"), run("joint-limit", "daqp"), run("joint-limit", "pinv")
    q_max = s.robot.q_max[0]
    assert s.robot.q_max[0] - s.robot.q_min[0] < 0.2  # a tight limit on the carriage
    assert qp.ok and qp.q[:, 0].max() <= q_max + 1e-9
    at_limit = np.abs(qp.q[:, 0] - q_max) < 1e-6
    assert at_limit.sum() > 0.5 * qp.n_steps  # the bound is active most of the run
    relaxed = np.flatnonzero(qp.status == "relaxed")
    assert relaxed.size > 10 and qp.t[relaxed[0]] > 3.0  # the task is given up at the end only
    assert np.all(qp.status[: relaxed[0]] == "optimal")
    assert base.q[:, 0].max() > q_max + 0.5  # the baseline runs far past the limit


def test_many_obstacles_scene_holds_the_margin_at_several_obstacles() -> None:
    s, qp, base = (
        scene("many-obstacles"),
        run("many-obstacles", "daqp"),
        run("many-obstacles", "pinv"),
    )
    assert len(s.obstacles) >= 20
    assert qp.ok and exact_where_optimal(qp)
    check_run(s, qp)
    assert qp.min_clearance.min() > damper(s).margin - 5e-4
    tight = tight_rows(s, qp)
    obstacles = {label.split("/")[1] for label in tight if "/obstacles[" in label}
    low_clamps = {"obstacles[0]", "obstacles[1]", "obstacles[2]"}
    assert len(obstacles & low_clamps) >= 2  # the low clamps in turn
    assert base.min_clearance.min() < -0.003


@pytest.mark.parametrize("backend", QP)
def test_priorities_scene_keeps_height_and_heading_while_the_reach_runs_out(backend: str) -> None:
    s, qp = scene("reach-priorities"), run("reach-priorities", backend)
    check_run(s, qp)  # safe to send: every step, every limit kept, the end within 2.5 cm
    assert qp.limits_kept.all() and not qp.start_broken
    e = np.abs(qp.tracking_error)
    assert e[:, 2].max() <= 0.05e-3  # m: the probe's height, every sample
    assert e[:, 3].max() <= 1e-4  # rad: its heading
    assert e[:, 0].max() >= 5e-3  # m: while it lags along the weld
    assert qp.levels == ("tool h, alpha", "tool l, z")
    assert qp.level_error[:, 0].max() <= 1e-6  # level 1 kept exactly in every step
    gave_way = qp.level_error[:, 1] > 1e-6
    assert gave_way.sum() > 100 and np.all(qp.status[gave_way] == "relaxed")
    one = plan(dataclasses.replace(s, tasks=()), backend)  # the tool as one task
    assert one.limits_kept.all() and np.abs(one.tracking_error[:, 2]).max() > 1e-3


def test_priorities_scene_baseline_drives_the_carriage_past_its_limit() -> None:
    s, base = scene("reach-priorities"), run("reach-priorities", "pinv")
    assert base.level_error.max() < 1e-9  # both levels met, as the baseline holds no limit
    assert base.q[:, 0].max() > s.robot.q_max[0] + 0.5
