"""The start configuration: inside the pipe is refused; below the minimum height or within an
obstacle's margin is allowed, and the QP then lets it get no worse and pushes it out."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import SceneError, plan
from dvqp.cli import main
from dvqp.scenes.scene import loads
from tests.common import Q0
from tests.scenes.test_scene import BASE, SRC, edit


def start_at(changes: dict[int, float], text: str = BASE) -> str:
    """The scene text with ``q0[j] += delta`` for each ``j: delta``."""
    q = np.array(Q0)
    for joint, delta in changes.items():
        q[joint] += delta
    return edit(text, str(Q0), str([float(v) for v in q]))


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (
            {1: 0.3},
            "robot.q0: body point 5 (frame 'point5') starts inside the pipe: h = -0.00987 m",
        ),
        (
            {2: 0.6},
            "robot.q0: body point 4 (frame 'point4') starts inside the pipe: h = -0.01604 m",
        ),
        ({5: -0.6}, "robot.q0: the tool (frame 'tool') starts inside the pipe: h = -0.005759 m"),
    ],
    ids=["body point", "first of several", "the tool alone"],
)
def test_a_start_inside_the_pipe_is_refused_naming_the_part_and_its_height(
    changes: dict[int, float], message: str
) -> None:
    with pytest.raises(SceneError) as info:
        loads(start_at(changes), SRC)
    assert str(info.value) == f"{SRC}: {message}"


def test_the_command_line_refuses_it_with_exit_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "inside.toml"
    scene.write_text(start_at({1: 0.3}), encoding="utf-8")
    assert main(["plan", str(scene), "-o", str(tmp_path / "out.npz")]) == 2
    message = "robot.q0: body point 5 (frame 'point5') starts inside the pipe: h = -0.00987 m"
    assert capsys.readouterr().err == f"dvqp: {scene}: {message}\n"
    assert [p.name for p in tmp_path.iterdir()] == ["inside.toml"]


def test_a_start_below_the_minimum_height_gets_no_lower_and_rises() -> None:
    pytest.importorskip("daqp")
    text = start_at({3: -0.3})  # point 5 at h = 15 mm, the tool at 6 mm
    text = edit(text, "[constraints]\n", "[constraints]\nmin_height = 0.02\n")
    scene = loads(edit(text, "duration = 0.1", "duration = 1.0"), SRC)
    height = plan(scene, "daqp").points[:, 4, 2]
    assert height[0] == pytest.approx(0.0150, abs=1e-4)
    assert height.min() >= height[0] - 1e-9
    assert height[-1] > height[0]  # the orbital term lifts it (slowly); the damper holds it


def test_a_start_within_an_obstacles_margin_gets_no_closer() -> None:
    pytest.importorskip("daqp")
    text = edit(
        BASE, "center = [0.10, 0.20]\nradius = 0.05", "center = [0.137, 0.44]\nradius = 0.063"
    )
    scene = loads(edit(text, "duration = 0.1", "duration = 1.0"), SRC)
    clearance = plan(scene, "daqp").min_clearance
    assert 0.0 < clearance[0] < 0.01  # within the 1 cm margin
    assert clearance.min() >= clearance[0] - 1e-4  # no closer than at the start (tolerance)
