"""``[[tasks]]`` in a scene file: read into the tasks at their priorities, every key checked
like any field (one line naming the file and the field); without it, the paper's step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import FrameTask, PointTask, PostureTask, SceneError, ToolTask, plan
from dvqp.scenes.scene import load_scene, loads

ROOT = Path(__file__).resolve().parents[2]
SRC = "scenes/x.toml"
JOINT_LIMIT = (ROOT / "scenes" / "joint-limit.toml").read_text(encoding="utf-8")
URDF = (ROOT / "scenes" / "urdf-arm.toml").read_text(encoding="utf-8")


def with_tasks(text: str, tasks: str) -> str:
    """``text`` with ``tasks`` (TOML of ``[[tasks]]`` tables) before its ``[motion]``."""
    at = text.index("[motion]")
    return text[:at] + tasks + "\n" + text[at:]


def test_without_tasks_a_scene_is_the_papers_step() -> None:
    s = loads(JOINT_LIMIT, SRC)
    assert s.tasks == () and [type(t) for t in s.spec().tasks] == [ToolTask]
    assert s.spec().tasks[0].components == ("l", "z", "h", "alpha")


def test_each_kind_is_read_with_its_keys() -> None:
    s = loads(
        with_tasks(
            JOINT_LIMIT,
            """
[[tasks]]
kind = "tool"
components = ["alpha", "h"]

[[tasks]]
kind = "tool"
components = ["l", "z"]
priority = 2
weight = 0.5

[[tasks]]
kind = "point"
point = 2
components = ["h"]
target = [0.07]
gain = 2.0
priority = 3

[[tasks]]
kind = "posture"
priority = 4
""",
        ),
        SRC,
    )
    tool, place, point, posture = s.tasks
    assert isinstance(tool, ToolTask) and tool.components == ("h", "alpha")
    assert (place.priority, place.weight) == (2, 0.5)
    assert isinstance(point, PointTask) and point.point == 2 and point.components == ("h",)
    assert point.target is not None and point.target[2] == 0.07 and point.gain == 2.0
    assert isinstance(posture, PostureTask) and posture.target is not None
    np.testing.assert_array_equal(posture.target, s.q0)  # default: the start
    assert s.spec().level_names == ("tool h, alpha", "tool l, z", "point3 h", "posture")


def test_a_frame_task_names_a_frame_of_the_model() -> None:
    s = loads(
        with_tasks(
            URDF,
            """
[[tasks]]
kind = "tool"

[[tasks]]
kind = "frame"
frame = "point3"
components = ["position"]
priority = 2
""",
        ),
        SRC,
        base_dir=ROOT / "scenes",
    )
    frame = s.tasks[1]
    assert isinstance(frame, FrameTask) and frame.frame == "point3"
    assert frame.position is not None  # where it starts
    np.testing.assert_allclose(frame.pose(s.q0)[0], frame.position, atol=1e-15)


def test_the_tool_as_one_task_of_priority_one_is_the_scenes_own_run() -> None:
    given = loads(with_tasks(JOINT_LIMIT, '[[tasks]]\nkind = "tool"\n'), SRC)
    plain = loads(JOINT_LIMIT, SRC)
    a, b = plan(given, "daqp"), plan(plain, "daqp")
    np.testing.assert_array_equal(a.q, b.q)
    assert list(a.status) == list(b.status)


BAD = [
    ('kind = "pose"', "tasks[0].kind: unknown kind 'pose' (known: tool, point, posture, frame)"),
    (
        'kind = "tool"\ncomponents = ["l", "x"]',
        "tasks[0].components: unknown component 'x' (known: l, z, h, alpha)",
    ),
    (
        'kind = "tool"\ncomponents = []',
        "tasks[0].components: must not be empty (choose from l, z, h, alpha)",
    ),
    (
        'kind = "tool"\npriority = 0',
        "tasks[0].priority: must be an integer >= 1 (1 the highest), got 0",
    ),
    (
        'kind = "tool"\npriority = 1.5',
        "tasks[0].priority: must be an integer >= 1 (1 the highest), got 1.5",
    ),
    (
        'kind = "tool"\npriority = true',
        "tasks[0].priority: must be an integer >= 1 (1 the highest), got True",
    ),
    ('kind = "tool"\nweight = 0', "tasks[0].weight: must be > 0, got 0.0"),
    (
        'kind = "point"\npoint = 5',
        "tasks[0].point: index 5 is out of range: the arm has body points 0 .. 4",
    ),
    (
        'kind = "point"\npoint = 1\ncomponents = ["h"]\ntarget = [0.1, 0.2]',
        "tasks[0].target: expected 1 numbers (h) or 3 ([l, z, h]), got [0.1, 0.2]",
    ),
    ('kind = "point"', "tasks[0].point: required field is missing"),
    (
        'kind = "tool"\npoint = 1',
        "tasks[0].point: unknown key (allowed: kind, priority, weight, components)",
    ),
    (
        'kind = "frame"\nframe = "elbow"',
        "tasks[0].frame: no frame named 'elbow' (model has: universe, ",
    ),
    (
        'kind = "posture"\ntarget = [0.0, 1.0]',
        "tasks[0].target: expected an array of 13 numbers, got 2 values",
    ),
    (
        'kind = "tool"\n\n[[tasks]]\nkind = "posture"',
        "tasks[0]: level 1 (tool; posture) cannot be met even alone: it has 17 rows for 13 joints",
    ),
    (
        'kind = "tool"\ncomponents = ["h"]\n\n[[tasks]]\nkind = "tool"\ncomponents = ["h", "l"]\n'
        "priority = 2",
        "tasks[1].components: 'h' is already held by tasks[0]",
    ),
]


@pytest.mark.parametrize(("table", "message"), BAD)
def test_bad_tasks_are_refused_in_one_line_naming_the_field(table: str, message: str) -> None:
    with pytest.raises(SceneError) as info:
        loads(with_tasks(JOINT_LIMIT, f"[[tasks]]\n{table}\n"), SRC)
    text = str(info.value)
    assert text.startswith(f"{SRC}: {message}"), text
    assert "\n" not in text


def test_the_bundled_priorities_scene_splits_the_tool() -> None:
    s = load_scene(ROOT / "scenes" / "reach-priorities.toml")
    assert s.spec().level_names == ("tool h, alpha", "tool l, z")
