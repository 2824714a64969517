"""Obstacles are named one way everywhere: by a scene's ``name`` key, else ``obstacles[j]``
(0-based, as scene errors name them), in damper rows, reports, failures and the console."""

from __future__ import annotations

import pytest

from dvqp import SceneError, plan
from dvqp.console.recording import Sample
from dvqp.geometry import ObstacleSet
from dvqp.geometry.shapes import Circle
from dvqp.limits import ObstacleDamper
from dvqp.resolution.registry import make_resolver
from dvqp.run.comparison import run_error, summarize
from dvqp.scenes import loads
from dvqp.step import Stepper
from tests.runs import SCENES, run

PAPER = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
SRC = "scenes/named.toml"
LOWER = "[[obstacles]]          # lower inlet, between the rail and the weld\n"


def named(name: str) -> str:
    """The paper scene with its second obstacle (the lower inlet) given ``name`` (TOML)."""
    assert LOWER in PAPER
    return PAPER.replace(LOWER, f"{LOWER}name = {name}\n")


def damper_labels(scene_text: str) -> tuple[str, ...]:
    scene = loads(scene_text, SRC)
    (damper,) = (lim for lim in scene.limits if isinstance(lim, ObstacleDamper))
    return damper.labels(scene.robot.part_names)


def test_without_names_labels_index_the_obstacles_from_0_as_scene_errors_do() -> None:
    labels = damper_labels(PAPER)
    parts = ("point1", "point2", "point3", "point4", "point5", "probe")
    assert labels[:6] == tuple(f"{part}/obstacles[0]" for part in parts)
    assert "holder/obstacles[1]" in labels and not any("obstacles[2]" in x for x in labels)
    row = summarize(loads(PAPER, SRC), run("paper-two-inlets", "daqp"))
    assert row["closest"] == "link4/obstacles[1]"  # the lower inlet, scenes' obstacles[1]


def test_a_named_obstacle_labels_its_pairs_in_rows_reports_failures_and_the_console() -> None:
    pytest.importorskip("daqp")
    text = named('"inlet-lower"')
    labels = damper_labels(text)
    assert "point4/inlet-lower" in labels and "holder/inlet-lower" in labels
    assert "probe/obstacles[0]" in labels  # the unnamed upper inlet keeps its index
    assert not any("obstacles[1]" in x for x in labels)
    scene = loads(text, SRC)
    qp = plan(scene, "daqp")
    assert summarize(scene, qp)["closest"] == "link4/inlet-lower"
    why = run_error(scene, plan(scene, "pinv"))  # the baseline enters the lower inlet
    assert why is not None and "/inlet-lower clearance" in why
    resolver = make_resolver("daqp", scene.spec())
    stepper = Stepper(scene.robot, scene.pipe_radius, resolver, qp.q[-1], scene.dt, scene.obstacles)
    stepper.start(qp.q[-1])
    assert Sample.of(stepper).closest == "link4/inlet-lower"


BAD_NAMES = [
    ('""', "obstacles[1].name: must be a non-empty name without surrounding spaces"),
    ('" lower"', "obstacles[1].name: must be a non-empty name without surrounding spaces"),
    ("42", "obstacles[1].name: expected a string, got a number"),
    (
        '"in/let"',
        "obstacles[1].name: 'in/let': must be printable and have no '/' "
        "(labels read 'point3/<name>')",
    ),
    (
        '"in\\nlet"',
        "obstacles[1].name: 'in\\nlet': must be printable and have no '/' "
        "(labels read 'point3/<name>')",
    ),
    (
        '"height"',
        "obstacles[1].name: 'height' reads as another label (height, probe, holder, "
        "pointN, linkN, obstacles[N]): choose another",
    ),
    (
        '"obstacles[0]"',
        "obstacles[1].name: 'obstacles[0]' reads as another label (height, "
        "probe, holder, pointN, linkN, obstacles[N]): choose another",
    ),
]


@pytest.mark.parametrize(("name", "message"), BAD_NAMES, ids=[n for n, _ in BAD_NAMES])
def test_a_bad_name_is_refused_naming_the_file_and_the_field(name: str, message: str) -> None:
    with pytest.raises(SceneError) as info:
        loads(named(name), SRC)
    assert str(info.value) == f"{SRC}: {message}"


def test_a_name_used_twice_is_refused_at_the_second() -> None:
    upper = "[[obstacles]]          # upper"
    text = named('"inlet"').replace(upper, f'{upper}\nname = "inlet"\n#')
    with pytest.raises(SceneError) as info:
        loads(text, SRC)
    assert str(info.value) == f"{SRC}: obstacles[1].name: 'inlet' already names obstacles[0]"


def test_an_obstacle_set_in_code_takes_names_too() -> None:
    shapes = [Circle([0.0, 0.5], 0.05), Circle([0.2, 0.5], 0.05)]
    assert ObstacleSet(shapes).labels == ("obstacles[0]", "obstacles[1]")
    assert ObstacleSet(shapes, [None, "clamp"]).labels == ("obstacles[0]", "clamp")
    with pytest.raises(ValueError, match="names: expected 2, got 1"):
        ObstacleSet(shapes, ["clamp"])
