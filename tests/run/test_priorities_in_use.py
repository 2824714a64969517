"""Strict priorities as users meet them, in whole runs: a JOG's levels hold their reference
(the loop closed on the integrated command), the baseline nests a level that can only be met
in least squares as the lexicographic QP meets it, a step is relaxed only where a level gave
way, and a motion no task follows is refused at load."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import dvqp
from dvqp.cli import main
from dvqp.run.levels import DRIFT_ANGLE, DRIFT_LENGTH, KEPT, level_figures
from tests.runs import QP, SCENES, run, scene

FOUR_LEVELS = """
name = "four-levels"

[pipe]
radius = 0.254
weld = 0.35

[robot]
model = "ndt13"
link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
q0 = [1.5708, -0.048, 0.068, 0.026, 0.08, 0.032, 0.088, -0.078, -0.088, 0.003, -0.434, 0.116,
      -0.278]
qd_max = 1.5

[objective]
orbital_level = 0.08
k_height = 100.0

[constraints]
min_height = 0.02

[[tasks]]
kind = "tool"
components = ["h", "alpha"]

[[tasks]]
kind = "tool"
components = ["l", "z"]
priority = 2

[[tasks]]
kind = "point"
point = 2
components = ["h"]
priority = 3

[[tasks]]
kind = "posture"
priority = 4

[motion]
dt = 0.005

[[motion.jog]]
duration = 1.0
velocity = [0.03, 0.0, 0.0, 0.0]
"""
"""Four levels, a posture at the bottom (13 rows in the 8 joints the others leave), nothing
active: met in least squares, never relaxed."""


@functools.cache
def four_levels(backend: str) -> dvqp.Trajectory:
    return dvqp.plan(dvqp.scenes.loads(FOUR_LEVELS, "four-levels.toml"), backend)


def test_the_baseline_plans_a_posture_below_three_levels_as_every_qp_backend_does() -> None:
    reference = four_levels("pinv")
    assert reference.success.all()
    for backend in QP:
        traj = four_levels(backend)
        assert traj.success.all(), backend
        assert np.abs(traj.q - reference.q).max() <= 1e-6, backend
        assert not np.any(traj.status == "relaxed"), backend
        figures = level_figures(traj)
        assert [f.gave_way for f in figures] == [0, 0, 0, 0]
        assert figures[3].least_squares > 0  # the posture: least squares, not given way
        assert all(f.kept for f in figures[:3]), [f.words() for f in figures]


def test_the_point_task_holds_its_height_under_the_posture() -> None:
    traj = four_levels("daqp")
    height = traj.points[:, 2, 2]
    assert np.abs(height - height[0]).max() <= 1e-4


def test_a_jog_holds_its_first_level_to_the_reference_while_the_second_lags() -> None:
    s, traj = scene("jog-priorities"), run("jog-priorities", "daqp")
    assert traj.success.all()
    error = np.abs(traj.tracking_error)
    assert error[:, 2].max() <= DRIFT_LENGTH and error[:, 3].max() <= DRIFT_ANGLE
    assert np.hypot(error[:, 0], error[:, 1]).max() >= 5e-3  # the reach ran out: l, z lag
    assert np.all(traj.q >= s.robot.q_min - 1e-9) and np.all(traj.q <= s.robot.q_max + 1e-9)
    level = level_figures(traj)[0]
    assert level.kept and level.words().startswith("kept exactly (within 0.05 mm, 0.1 mrad)")


def test_an_open_loop_jog_drifts_off_its_first_level_and_says_so() -> None:
    text = (SCENES / "jog-priorities.toml").read_text(encoding="utf-8")
    opened = text.replace("[motion]\n", "[motion]\ngain = 0.0\n", 1)
    assert opened != text
    traj = dvqp.plan(dvqp.scenes.loads(opened, "open-loop.toml"), "daqp")
    level = level_figures(traj)[0]
    assert level.met and level.drifted and "drifted" in level.words()
    assert np.abs(traj.tracking_error[:, 3]).max() > DRIFT_ANGLE


def random_levels(draw: st.DrawFn) -> str:
    """``[[tasks]]`` of random levels: the tool's components over 1-3 priorities, maybe a body
    point's component and a posture below some of them."""
    components = draw(st.permutations(["l", "z", "h", "alpha"]))
    cuts = sorted(draw(st.sets(st.integers(1, 3), max_size=2)))
    groups = [components[a:b] for a, b in zip([0, *cuts], [*cuts, 4], strict=True)]
    tables = [
        f'[[tasks]]\nkind = "tool"\ncomponents = {list(g)!r}\npriority = {p}\n'
        for p, g in enumerate(groups, 1)
    ]
    if draw(st.booleans()):
        point, part = draw(st.integers(0, 4)), draw(st.sampled_from(["l", "z", "h"]))
        priority = draw(st.integers(1, len(groups) + 1))
        tables.append(
            f'[[tasks]]\nkind = "point"\npoint = {point}\ncomponents = ["{part}"]\n'
            f"priority = {priority}\n"
        )
    if draw(st.booleans()):
        tables.append(f'[[tasks]]\nkind = "posture"\npriority = {len(groups) + 2}\n')
    return "\n".join(tables)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.composite(random_levels)(), st.sampled_from([(0.03, 0.0), (0.0, 0.02), (0.02, 0.3)]))
def test_status_and_level_figures_agree_on_random_levels(levels: str, jog: tuple) -> None:  # type: ignore[type-arg]
    start = FOUR_LEVELS.index("[[tasks]]")
    text = FOUR_LEVELS[:start] + levels + FOUR_LEVELS[FOUR_LEVELS.index("\n[motion]") :]
    text = text.replace("duration = 1.0", "duration = 0.3").replace(
        "velocity = [0.03, 0.0, 0.0, 0.0]", f"velocity = [{jog[0]}, 0.0, 0.0, {jog[1]}]"
    )
    s = dvqp.scenes.loads(text, "random-levels.toml")
    baseline, traj = dvqp.plan(s, "pinv"), dvqp.plan(s, "daqp")
    assert baseline.success.all() and traj.success.all()
    relaxed = traj.status == "relaxed"
    missed = traj.level_error > KEPT
    assert not np.any(relaxed & ~missed.any(axis=1))  # relaxed: some level gave way
    figures = level_figures(traj)
    for k, level in enumerate(figures):
        assert level.gave_way == int(np.sum(missed[:, k] & relaxed))
        assert level.least_squares == int(np.sum(missed[:, k] & ~relaxed))
    assert all(f.gave_way == 0 for f in level_figures(baseline))  # it holds no limit
    if not relaxed.any():  # nothing bound: the QP is the nested baseline, level by level
        end = min(traj.brake_start, baseline.brake_start) + 1  # the stops differ
        assert np.abs(traj.q[:end] - baseline.q[:end]).max() <= 1e-6


PANDA_FRAME = """
[[tasks]]
kind = "frame"
frame = "panda_link7"

[[tasks]]
kind = "posture"
priority = 2
"""


def panda_text(tasks: str) -> str:
    text = (SCENES / "panda.toml").read_text(encoding="utf-8")
    return text.replace("[motion]", tasks + "\n[motion]", 1)


def test_a_frame_task_over_a_posture_on_the_panda_is_never_relaxed() -> None:
    held = PANDA_FRAME + '\n[[tasks]]\nkind = "tool"\npriority = 3\n'  # follows the JOG
    s = dvqp.scenes.loads(panda_text(held), str(SCENES / "panda-frame.toml"))
    traj = dvqp.plan(s, "daqp")
    assert traj.success.all()
    assert not np.any(traj.status == "relaxed")
    assert all(f.gave_way == 0 for f in level_figures(traj))


def test_a_jog_no_task_follows_is_refused_at_load(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(dvqp.SceneError, match=r"motion\.jog\[0\]\.velocity: commands the tool's l"):
        dvqp.scenes.loads(panda_text(PANDA_FRAME), str(SCENES / "panda-frame.toml"))


def test_a_jog_gain_belongs_to_a_jog(tmp_path) -> None:  # type: ignore[no-untyped-def]
    text = (SCENES / "reach-priorities.toml").read_text(encoding="utf-8")
    bad = tmp_path / "gain.toml"
    bad.write_text(text.replace("[motion]\n", "[motion]\ngain = 3.0\n", 1), encoding="utf-8")
    assert main(["plan", str(bad)]) == 2
    with pytest.raises(dvqp.SceneError, match=r"motion\.gain: a JOG's feedback gain; a path's"):
        dvqp.load_scene(bad)


def test_a_scene_names_a_body_point_as_its_reports_do() -> None:
    named = dvqp.scenes.loads(FOUR_LEVELS.replace("point = 2", 'point = "point3"'), "named.toml")
    point = next(t for t in named.tasks if isinstance(t, dvqp.PointTask))
    assert point.point == 2 and point.label == "point3 h"
    with pytest.raises(dvqp.SceneError, match=r"tasks\[2\]\.point: unknown body point 'knee'"):
        dvqp.scenes.loads(FOUR_LEVELS.replace("point = 2", 'point = "knee"'), "bad.toml")
    text = panda_text(
        '[[tasks]]\nkind = "tool"\n\n[[tasks]]\nkind = "point"\npoint = "panda_link4"\n'
        'components = ["h"]\npriority = 2\n'
    )
    panda = dvqp.scenes.loads(text, str(SCENES / "panda-point.toml"))
    assert next(t for t in panda.tasks if isinstance(t, dvqp.PointTask)).point == 1


def test_more_levels_than_the_cap_are_refused_at_load_and_in_the_api() -> None:
    from dvqp.resolution.spec import MAX_LEVELS

    many = "".join(
        f'[[tasks]]\nkind = "posture"\npriority = {p}\n' for p in range(2, MAX_LEVELS + 2)
    )
    text = FOUR_LEVELS.replace('[[tasks]]\nkind = "posture"\npriority = 4\n', many)
    with pytest.raises(dvqp.SceneError, match=rf"tasks: {MAX_LEVELS + 1} priorities: at most"):
        dvqp.scenes.loads(text, "many.toml")
    tasks = [dvqp.ToolTask(), *(dvqp.PostureTask(priority=p) for p in range(2, MAX_LEVELS + 2))]
    with pytest.raises(dvqp.ParameterError, match=f"at most {MAX_LEVELS} levels"):
        dvqp.StepSpec(tuple(tasks))
