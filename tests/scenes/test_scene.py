"""Scene files: parsing into typed objects and one exact message per class of invalid input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import KinematicState, SceneError, load_scene, plan
from dvqp.limits import (
    AccelerationLimit,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    ProbeHeight,
    SelfCollision,
    SurfaceHeight,
    TiltLimit,
)
from dvqp.scenes.scene import environment, loads
from tests.common import LINK_LENGTHS, ORBITAL_LEVEL, PIPE_RADIUS, Q0

SCENES = Path(__file__).resolve().parents[2] / "scenes"
SRC = "scenes/x.toml"

BASE = """
name = "test"
[pipe]
radius = 0.254
[robot]
model = "ndt13"
link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
q0 = {Q0}
[objective]
orbital_level = 0.08
k_height = 1.0
[[obstacles]]
center = [0.20, 0.45]
radius = 0.06
weight = 10.0
[[obstacles]]
center = [0.10, 0.20]
radius = 0.05
[constraints]
margin = 0.01
influence = 0.06
damper_gain = 0.5
[motion]
dt = 0.005
[[motion.jog]]
duration = 0.1
velocity = [0.05, 0.0, 0.0, 0.0]
""".replace("{Q0}", str(Q0))

PATH = BASE.replace(
    """[[motion.jog]]
duration = 0.1
velocity = [0.05, 0.0, 0.0, 0.0]""",
    """[motion.path]
waypoints = [[0.30, 0.35, 0.082, 0.0], [0.35, 0.35, 0.082, 0.0]]
speed = 0.05""",
)


def edit(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def test_a_valid_scene_becomes_typed_objects() -> None:
    scene = loads(BASE, SRC)
    assert (scene.name, scene.source, scene.mode, scene.pipe_radius) == ("test", SRC, "jog", 0.254)
    assert scene.robot.n == 13 and scene.robot.n_points == 5
    np.testing.assert_array_equal(scene.q0, Q0)
    assert [o.radius for o in scene.obstacles] == [0.06, 0.05]
    assert [o.weight for o in scene.obstacles] == [10.0, 1.0]  # weight defaults to 1
    np.testing.assert_array_equal(scene.obstacles[0].center, [0.20, 0.45])
    assert scene.orbital_level == ORBITAL_LEVEL and scene.objective.gain == 1.0
    assert scene.objective.terms[0].level == ORBITAL_LEVEL
    kinds = (
        JointPositionLimit,
        JointVelocityLimit,
        AccelerationLimit,
        ObstacleDamper,
        SurfaceHeight,
        ProbeHeight,
        TiltLimit,
        SelfCollision,
    )
    assert [type(limit) for limit in scene.limits] == list(kinds)
    acceleration, damper, height, probe, tilt, self_collision = scene.limits[2:]
    np.testing.assert_array_equal(acceleration.qdd_max, np.full(13, 10.0))
    assert (self_collision.margin, self_collision.gain) == (0.02, 0.5)
    assert (damper.margin, damper.influence, damper.gain) == (0.01, 0.06, 0.5)
    assert (height.min_height, height.gain) == (0.0, 0.5)
    assert (probe.floor, probe.gain, tilt.min_tilt, tilt.gain) == (0.0, 0.5, 0.2, 0.5)
    assert damper.obstacles is scene.obstacles is scene.objective.terms[1].obstacles
    assert scene.dt == 0.005 and len(scene.jog) == 1 and scene.path is None
    np.testing.assert_array_equal(scene.weights, np.ones(13))
    np.testing.assert_array_equal(scene.robot.qd_max, np.full(13, 1.5))
    assert scene.text == BASE and scene.weld is None


def test_per_joint_and_per_point_values_are_read_as_given() -> None:
    text = edit(BASE, "q0 = [", "weights = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13]\nq0 = [")
    text = edit(text, "k_height = 1.0", "k_height = [1, 2, 3, 4, 5]")
    text = edit(text, "radius = 0.254", "radius = 0.254\nweld = 0.35")
    text = edit(text, "q0 = [", "q_min = [-inf" + ", -3" * 12 + "]\nq_max = inf\nq0 = [")
    scene = loads(text, SRC)
    assert scene.robot.q_min[0] == -np.inf and scene.robot.q_min[1] == -3.0
    assert np.all(scene.robot.q_max == np.inf)
    np.testing.assert_array_equal(scene.weights, np.arange(1, 14))
    np.testing.assert_array_equal(scene.objective.terms[0].k_height, [1, 2, 3, 4, 5])
    assert scene.weld == 0.35


def test_a_path_scene_keeps_its_waypoints_and_defaults() -> None:
    scene = loads(PATH, SRC)
    assert scene.mode == "path" and scene.jog == ()
    assert scene.path is not None
    assert scene.path.waypoints.shape == (2, 4)
    assert (scene.path.speed, scene.path.gain, scene.path.tolerance) == (0.05, 5.0, 0.005)


def test_the_bundled_paper_scene_puts_the_arm_where_the_issue_says() -> None:
    scene = load_scene(SCENES / "paper-two-inlets.toml")
    np.testing.assert_array_equal(scene.robot.q_max[1:], np.pi)
    state = KinematicState.compute(scene.robot, scene.q0, scene.pipe_radius)
    expected = [
        (0.004, 0.100, 0.08),
        (0.012, 0.249, 0.08),
        (0.024, 0.399, 0.08),
        (0.137, 0.372, 0.079),
        (0.252, 0.350, 0.079),
    ]
    np.testing.assert_allclose(state.points, expected, atol=1.5e-3)
    np.testing.assert_allclose(state.tool, [0.297, 0.350, 0.082, 0.0], atol=1e-3)
    assert scene.weld == 0.35 and len(scene.obstacles) == 2
    assert scene.pipe_radius == PIPE_RADIUS
    np.testing.assert_array_equal(scene.robot.model.nq, len(LINK_LENGTHS) + 6)


def test_every_bundled_scene_loads_and_has_a_readme_line() -> None:
    readme = (SCENES / "README.md").read_text(encoding="utf-8")
    files = sorted(SCENES.glob("*.toml"))
    assert len(files) >= 5
    for path in files:
        scene = load_scene(path)
        assert scene.name == path.stem
        assert f"`{path.name}`" in readme


INVALID = [
    ("missing field", ("radius = 0.254\n", ""), "pipe.radius: required field is missing"),
    ("missing section", ("[pipe]\nradius = 0.254\n", ""), "pipe: required field is missing"),
    (
        "wrong type",
        ("radius = 0.05\n", 'radius = "big"\n'),
        "obstacles[1].radius: expected a number, got a string",
    ),
    (
        "boolean is no number",
        ("dt = 0.005", "dt = true"),
        "motion.dt: expected a number, got a boolean",
    ),
    (
        "element type",
        ("-0.048, 0.068", '-0.048, "a"'),
        "robot.q0[2]: expected a number, got a string",
    ),
    (
        "table expected",
        ("[pipe]\nradius = 0.254\n", "pipe = 0.254\n"),
        "pipe: expected a table, got a number",
    ),
    (
        "wrong length",
        ("0.15, 0.06]", "0.06]"),
        "robot.link_lengths: expected an array of 7 numbers, got 6 values",
    ),
    (
        "wrong length per joint",
        ("0.116, -0.278]", "0.116]"),
        "robot.q0: expected an array of 13 numbers, got 12 values",
    ),
    (
        "wrong length per point",
        ("k_height = 1.0", "k_height = [1.0, 1.0]"),
        "objective.k_height: expected a number or an array of 5 numbers, got 2 values",
    ),
    (
        "negative radius",
        ("radius = 0.05", "radius = -0.05"),
        "obstacles[1].radius: must be > 0, got -0.05",
    ),
    ("not finite", ("radius = 0.254", "radius = inf"), "pipe.radius: must be finite, got inf"),
    ("dt zero", ("dt = 0.005", "dt = 0"), "motion.dt: must be > 0, got 0.0"),
    ("dt negative", ("dt = 0.005", "dt = -0.01"), "motion.dt: must be > 0, got -0.01"),
    (
        "unknown key",
        ("orbital_level = 0.08", "orbital_levle = 0.08"),
        "objective.orbital_levle: unknown key (did you mean 'orbital_level'?)",
    ),
    ("unknown section", ("[pipe]", "[pipes]"), "pipes: unknown key (did you mean 'pipe'?)"),
    (
        "unknown key in array",
        ("weight = 10.0", "wieght = 10.0"),
        "obstacles[0].wieght: unknown key (did you mean 'weight'?)",
    ),
    (
        "q0 outside the limits",
        ("q0 = [", "q_min = -1.0\nq_max = 1.0\nq0 = ["),
        "robot.q0[0]: 1.5708 rad is outside [q_min, q_max] = [-1, 1] rad",
    ),
    (
        "limits crossed",
        ("q0 = [", "q_min = 2.0\nq_max = 1.0\nq0 = ["),
        "robot.q_min: must be <= q_max for every joint",
    ),
    ("zero velocity limit", ("q0 = [", "qd_max = 0\nq0 = ["), "robot.qd_max: must be > 0, got 0.0"),
    (
        "zero weight",
        ("q0 = [", "weights = 0.0\nq0 = ["),
        "robot.weights: must be >= 1e-06, got 0.0",
    ),
    ("negative link", ("[0.334,", "[-0.334,"), "robot.link_lengths[0]: must be >= 0, got -0.334"),
    ("unknown model", ('"ndt13"', '"ndt12"'), "robot.model: unknown model 'ndt12' (known: ndt13)"),
    (
        "model and urdf",
        ('model = "ndt13"', 'model = "ndt13"\nurdf = "a.urdf"'),
        "robot: give exactly one of 'model' (built in) or 'urdf' (a file)",
    ),
    (
        "negative objective weight",
        ("k_height = 1.0", "k_height = -1.0"),
        "objective.k_height: must be >= 0, got -1.0",
    ),
    (
        "damper gain",
        ("damper_gain = 0.5", "damper_gain = 2"),
        "constraints.damper_gain: must be in (0, 1], got 2.0",
    ),
    (
        "influence below margin",
        ("influence = 0.06", "influence = 0.005"),
        "constraints.influence: must be finite and > margin",
    ),
    (
        "jog duration",
        ("duration = 0.1", "duration = 0"),
        "motion.jog[0].duration: must be > 0, got 0.0",
    ),
    (
        "jog velocity length",
        ("[0.05, 0.0, 0.0, 0.0]", "[0.05, 0.0]"),
        "motion.jog[0].velocity: expected an array of 4 numbers, got 2 values",
    ),
    (
        "no motion",
        ("[[motion.jog]]\nduration = 0.1\nvelocity = [0.05, 0.0, 0.0, 0.0]\n", ""),
        "motion: give exactly one of [[motion.jog]] segments, a [motion.path] or a [motion.saddle]",
    ),
    (
        "singular start",
        ("[0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]", "[0, 0, 0, 0, 0, 0, 0]"),
        "robot.q0: singular configuration: frame 'point1' lies on the pipe axis (rho = 0 m)",
    ),
    (
        "nan",
        ("orbital_level = 0.08", "orbital_level = nan"),
        "objective.orbital_level: must be finite, got nan",
    ),
    (
        "obstacle swallows the tool",
        ("center = [0.20, 0.45]", "center = [0.2973, 0.40]"),
        "obstacles[0]: covers the tool's start point [l, z] = [0.2973, 0.35] m "
        "(10 mm inside the circle)",
    ),
    # sane bounds of physical quantities, the bound in the message
    (
        "huge pipe",
        ("radius = 0.254", "radius = 1e300"),
        "pipe.radius: must be <= 100 m, got 1e+300",
    ),
    (
        "tiny pipe",
        ("radius = 0.254", "radius = 1e-9"),
        "pipe.radius: must be >= 0.001 m, got 1e-09",
    ),
    (
        "far weld",
        ("radius = 0.254", "radius = 0.254\nweld = -1e9"),
        "pipe.weld: must be >= -1000 m, got -1000000000.0",
    ),
    ("long link", ("[0.334,", "[1e3,"), "robot.link_lengths[0]: must be <= 10 m, got 1000.0"),
    (
        "far start angle",
        ("q0 = [1.5708", "q_min = -inf\nq_max = inf\nq0 = [1e300"),
        "robot.q0[0]: must be <= 1000 rad, got 1e+300",
    ),
    (
        "huge finite limit",
        ("q0 = [", "q_max = 1e300\nq0 = ["),
        "robot.q_max: must be <= 1000 rad, got 1e+300",
    ),
    (
        "fast joint",
        ("q0 = [", "qd_max = 1e9\nq0 = ["),
        "robot.qd_max: must be <= 1000 rad/s, got 1000000000.0",
    ),
    (
        "heavy joint",
        ("q0 = [", "weights = 1e300\nq0 = ["),
        "robot.weights: must be <= 1e+06, got 1e+300",
    ),
    (
        "far obstacle",
        ("center = [0.10, 0.20]", "center = [0.10, 1e300]"),
        "obstacles[1].center[1]: must be <= 1000 m, got 1e+300",
    ),
    (
        "huge obstacle",
        ("radius = 0.05", "radius = 1e3"),
        "obstacles[1].radius: must be <= 100 m, got 1000.0",
    ),
    (
        "heavy obstacle",
        ("weight = 10.0", "weight = 1e300"),
        "obstacles[0].weight: must be <= 1e+06, got 1e+300",
    ),
    (
        "high orbit",
        ("orbital_level = 0.08", "orbital_level = 1e300"),
        "objective.orbital_level: must be <= 10 m, got 1e+300",
    ),
    (
        "orbit inside",
        ("orbital_level = 0.08", "orbital_level = -0.1"),
        "objective.orbital_level: must be >= 0, got -0.1",
    ),
    (
        "huge objective weight",
        ("k_height = 1.0", "k_height = [1, 1, 1e300, 1, 1]"),
        "objective.k_height[2]: must be <= 1e+06, got 1e+300",
    ),
    (
        "huge gain",
        ("k_height = 1.0", "k_height = 1.0\ngain = 1e300"),
        "objective.gain: must be <= 1e+06, got 1e+300",
    ),
    ("long dt", ("dt = 0.005", "dt = 5"), "motion.dt: must be <= 1 s, got 5.0"),
    (
        "longest duration",
        ("duration = 0.1", "duration = 1.7976931348623157e308"),
        "motion.jog[0].duration: must be <= 1e+06 s, got 1.7976931348623157e+308",
    ),
    (
        "fast jog",
        ("[0.05, 0.0, 0.0, 0.0]", "[0.05, 0.0, 0.0, 1e300]"),
        "motion.jog[0].velocity[3]: must be <= 10 rad/s, got 1e+300",
    ),
    (
        "too many jog steps",
        ("duration = 0.1", "duration = 1e6"),
        "motion: about 2e+08 steps of dt: too many (at most 1e+07)",
    ),
    (
        "any other number",
        ("margin = 0.01", "margin = 1e300"),
        "constraints.margin: must be <= 1e+06, got 1e+300",
    ),
    # what the parser itself cannot take
    (
        "deep arrays",
        ("radius = 0.254", "radius = 0.254\nweld = " + "[" * 1000 + "]" * 1000),
        "invalid TOML: values nested too deeply",
    ),
    (
        "deep tables",
        ("radius = 0.254", "radius = 0.254\nweld = " + "{a = " * 1000 + "1" + "}" * 1000),
        "invalid TOML: values nested too deeply",
    ),
    (
        "nested but parsed",
        ("radius = 0.254", "radius = 0.254\nweld = " + "[" * 100 + "]" * 100),
        "pipe.weld: expected a number, got an array",
    ),
    (
        "5000 digits",
        ("radius = 0.254", "radius = " + "1" * 5000),
        "invalid TOML: Exceeds the limit (4300 digits) for integer string conversion: "
        "value has 5000 digits",
    ),
    (
        "line break in a key",
        ("[pipe]", '[pipe]\n"a\\nb" = 1'),
        "pipe.a\\nb: unknown key (allowed: radius, weld)",
    ),
]


@pytest.mark.parametrize(
    ("edit_", "message"), [c[1:] for c in INVALID], ids=[c[0] for c in INVALID]
)
def test_invalid_scenes_raise_one_line_naming_file_and_field(
    edit_: tuple[str, str], message: str
) -> None:
    with pytest.raises(SceneError) as info:
        loads(edit(BASE, *edit_), SRC)
    assert str(info.value) == f"{SRC}: {message}"
    assert info.value.path == SRC and "\n" not in str(info.value)


INVALID_PATHS = [
    (
        "waypoint inside the pipe",
        ("[0.35, 0.35, 0.082, 0.0]", "[0.35, 0.35, -0.01, 0.0]"),
        "motion.path.waypoints[1]: h = -0.01 m is inside the pipe (must be >= 0)",
    ),
    (
        "one waypoint",
        ("[[0.30, 0.35, 0.082, 0.0], ", "["),
        "motion.path.waypoints: expected an array of at least 2 waypoints [l, z, h, α]",
    ),
    (
        "waypoint length",
        ("[0.35, 0.35, 0.082, 0.0]", "[0.35, 0.35]"),
        "motion.path.waypoints[1]: expected an array of 4 numbers, got 2 values",
    ),
    (
        "zero-length path",
        ("[0.35, 0.35, 0.082, 0.0]", "[0.30, 0.35, 0.082, 0.0]"),
        "motion.path.waypoints: the waypoints are all the same: nothing to follow",
    ),
    (
        "number out of range",
        ("speed = 0.05", "speed = 1" + "0" * 400),
        "motion.path.speed: must be <= 10 m/s, got 1.000e+400",
    ),
    (
        "too many steps",
        ("speed = 0.05", "speed = 1e-300"),
        "motion: about 1e+301 steps of dt: too many (at most 1e+07)",
    ),
    ("missing speed", ("speed = 0.05", ""), "motion.path.speed: required field is missing"),
    ("zero speed", ("speed = 0.05", "speed = 0.0"), "motion.path.speed: must be > 0, got 0.0"),
]


@pytest.mark.parametrize(
    ("edit_", "message"), [c[1:] for c in INVALID_PATHS], ids=[c[0] for c in INVALID_PATHS]
)
def test_invalid_paths_raise_one_line_naming_file_and_field(
    edit_: tuple[str, str], message: str
) -> None:
    with pytest.raises(SceneError) as info:
        loads(edit(PATH, *edit_), SRC)
    assert str(info.value) == f"{SRC}: {message}"


def test_invalid_toml_names_the_file() -> None:
    with pytest.raises(SceneError, match=r"^scenes/x\.toml: invalid TOML: .*line 2"):
        loads("name = 'a'\nthis is not toml\n", SRC)


def test_a_missing_file_is_a_scene_error(tmp_path: Path) -> None:
    missing = tmp_path / "nope.toml"
    with pytest.raises(SceneError) as info:
        load_scene(missing)
    assert str(info.value) == f"{missing}: cannot read: No such file or directory"


def test_a_urdf_path_resolves_from_the_scene_file(tmp_path: Path) -> None:
    text = edit(BASE, 'model = "ndt13"', 'urdf = "arms/arm.urdf"\npoints = ["a", "b"]\ntool = "c"')
    text = edit(text, "link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]\n", "")
    scene_file = tmp_path / "x.toml"
    scene_file.write_text(text, encoding="utf-8")
    with pytest.raises(SceneError) as info:
        load_scene(scene_file)
    urdf = tmp_path / "arms" / "arm.urdf"
    assert str(info.value) == f"{scene_file}: robot.urdf: no such file: {urdf}"


URDF = """<?xml version="1.0"?>
<robot name="snake5">
  <link name="base"/>
  {links}
</robot>
"""


def _urdf_arm() -> str:
    """A 6-joint arm on a carriage about the pipe axis; frames p2, p4, p6 and the tool."""
    joints = [
        ("z", "0 0 0"),
        ("x", "0.334 0 0.1"),
        ("y", "0 0 0.15"),
        ("x", "0 0 0.15"),
        ("y", "0 0 0.15"),
        ("x", "0 0 0.1"),
    ]
    parts, parent = [], "base"
    for i, (axis, xyz) in enumerate(joints, start=1):
        vec = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}[axis]
        parts.append(
            f'<link name="p{i}"/><joint name="j{i}" type="revolute"><parent link="{parent}"/>'
            f'<child link="p{i}"/><origin xyz="{xyz}"/><axis xyz="{vec}"/>'
            f'<limit lower="-3" upper="3" velocity="2" effort="1"/></joint>'
        )
        parent = f"p{i}"
    parts.append(
        f'<link name="tool"/><joint name="jt" type="fixed"><parent link="{parent}"/>'
        '<child link="tool"/><origin xyz="0 0 0.05"/></joint>'
    )
    return URDF.format(links="\n  ".join(parts))


def test_a_urdf_scene_loads_its_limits_and_plans(tmp_path: Path) -> None:
    (tmp_path / "arm.urdf").write_text(_urdf_arm(), encoding="utf-8")
    text = """
[pipe]
radius = 0.254
[robot]
urdf = "arm.urdf"
points = ["p2", "p4", "p6"]
tool = "tool"
q0 = [0.0, 0.1, 0.4, -0.2, -0.5, 0.3]
[objective]
orbital_level = 0.08
[motion]
dt = 0.01
[[motion.jog]]
duration = 0.2
velocity = [0.02, 0.01, 0.0, 0.0]
"""
    (tmp_path / "arm.toml").write_text(text, encoding="utf-8")
    scene = load_scene(tmp_path / "arm.toml")
    assert scene.robot.n == 6 and scene.robot.n_points == 3 and scene.name == "arm"
    np.testing.assert_array_equal(scene.robot.qd_max, np.full(6, 2.0))  # from the URDF
    np.testing.assert_array_equal(scene.robot.q_max, np.full(6, 3.0))
    traj = plan(scene, "pinv")
    assert traj.ok and traj.task_error.max() < 1e-9
    np.testing.assert_allclose(traj.tool[-1, :2] - traj.tool[0, :2], [0.004, 0.002], atol=2e-4)
    bad = text.replace('tool = "tool"', 'tool = "probe"')
    with pytest.raises(SceneError, match=r"robot\.tool: no frame named 'probe'"):
        loads(bad, "<string>", base_dir=tmp_path)


def test_environment_reads_what_a_plot_needs_without_building_the_robot() -> None:
    text = edit(BASE, 'model = "ndt13"', 'urdf = "gone.urdf"\npoints = ["a", "b"]\ntool = "c"')
    text = edit(text, "radius = 0.254", "radius = 0.254\nweld = 0.35")
    env = environment(text)
    assert (env.pipe_radius, env.orbital_level, env.weld) == (0.254, 0.08, 0.35)
    assert [o.radius for o in env.obstacles] == [0.06, 0.05]
    assert env.min_height is None  # not set: no line is drawn
    floored = edit(text, "margin = 0.01", "min_height = 0.03\nmargin = 0.01")
    assert environment(floored).min_height == 0.03


def _write_urdf_scene(folder: Path, urdf: str) -> Path:
    (folder / "arm.urdf").write_text(urdf, encoding="utf-8")
    text = edit(BASE, 'model = "ndt13"', 'urdf = "arm.urdf"\npoints = ["p2", "p4"]\ntool = "tool"')
    text = edit(text, "link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]\n", "")
    text = edit(text, f"q0 = {Q0}", "q0 = [0.0, 0.1, 0.4, -0.2, -0.5, 0.3]")
    text = edit(text, "center = [0.20, 0.45]", "center = [0.20, 0.95]")
    scene = folder / "arm.toml"
    scene.write_text(text, encoding="utf-8")
    return scene


def test_a_continuous_urdf_joint_is_a_revolute_joint_without_limits(tmp_path: Path) -> None:
    urdf = _urdf_arm().replace('name="j1" type="revolute"', 'name="j1" type="continuous"')
    scene = load_scene(_write_urdf_scene(tmp_path, urdf))
    assert scene.robot.n == 6 and scene.robot.q_min[0] == -np.inf and scene.robot.q_max[0] == np.inf
    np.testing.assert_array_equal(scene.robot.q_max[1:], 3.0)
    assert plan(scene, "pinv").ok


def test_urdf_errors_name_robot_urdf_and_keep_the_parser_quiet(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    floating = _urdf_arm().replace('name="j3" type="revolute"', 'name="j3" type="floating"')
    with pytest.raises(SceneError) as info:
        load_scene(_write_urdf_scene(tmp_path, floating))
    assert str(info.value) == (
        f"{tmp_path / 'arm.toml'}: robot.urdf: {tmp_path / 'arm.urdf'}: joint 'j3' has type "
        "'floating': dvqp takes only revolute, continuous, prismatic and fixed joints"
    )
    with pytest.raises(SceneError) as info:
        load_scene(_write_urdf_scene(tmp_path, "this is <not> XML"))
    assert str(info.value).endswith("arm.urdf: not well-formed XML: syntax error: line 1, column 0")
    bad = _urdf_arm().replace("</joint>", '<dynamics damping="x"/></joint>', 1)  # the parser's
    with pytest.raises(SceneError) as info:
        load_scene(_write_urdf_scene(tmp_path, bad))
    message = str(info.value)
    assert message.startswith(f"{tmp_path / 'arm.toml'}: robot.urdf: {tmp_path / 'arm.urdf'}: ")
    assert "cannot load URDF" in message and "damping value (x)" in message
    assert "\n" not in message
    assert capfd.readouterr() == ("", "")  # the C++ parser's own lines are kept off fd 1 and 2


def test_the_bundled_urdf_scene_runs_as_the_paper_scene() -> None:
    urdf, paper = load_scene(SCENES / "urdf-arm.toml"), load_scene(SCENES / "paper-two-inlets.toml")
    assert urdf.robot.n == 13 and urdf.robot.frame_names[-2:] == ("probe", "rail")
    assert urdf.robot.q_min[0] == -np.inf  # the carriage is a continuous joint
    np.testing.assert_allclose(plan(urdf, "pinv").q, plan(paper, "pinv").q, rtol=0, atol=1e-12)
