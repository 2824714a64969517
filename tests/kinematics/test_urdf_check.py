"""A robot file is checked before Pinocchio's parser sees it: what would crash the parser or
exhaust memory is refused in one line naming the file and the reason."""

from __future__ import annotations

import re
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dvqp import Robot, RobotFileError, SceneError, load_scene
from dvqp.kinematics.urdf_check import MAX_BYTES, read_urdf

ROOT = Path(__file__).resolve().parents[2]
ARM = (ROOT / "scenes" / "ndt13.urdf").read_text(encoding="utf-8")
SCENE = (ROOT / "scenes" / "urdf-arm.toml").read_text(encoding="utf-8")
CYCLE = '<joint name="cyc" type="fixed"><parent link="link5"/><child link="link2"/></joint>'
MEMORY = 2 << 30
"""Address space of a capped subprocess, bytes: a regression fails the test, not the machine."""


def chain(n: int, kind: str = "revolute") -> str:
    """A URDF chain of ``n`` joints of ``kind`` off the pipe axis, ending in the link ``probe``."""
    parts = ['<robot name="long">', '<link name="base"/>']
    for i in range(1, n + 1):
        parent = "base" if i == 1 else f"l{i - 1}"
        parts.append(
            f'<link name="l{i}"/><joint name="j{i}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="l{i}"/><origin xyz="{0.3 if i == 1 else 0} 0 0.01"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        )
    parts.append(
        f'<link name="probe"/><joint name="t" type="fixed"><parent link="l{n}"/>'
        '<child link="probe"/><origin xyz="0.05 0 0"/></joint></robot>'
    )
    return "\n".join(parts)


def capped_plan(folder: Path, urdf: str, n: int) -> tuple[subprocess.CompletedProcess[str], float]:
    """``dvqp plan`` of the bundled URDF scene with ``urdf`` as its arm (q0: n zeros, points the
    first two links), in a subprocess whose address space is capped at :data:`MEMORY`."""
    (folder / "arm.urdf").write_text(urdf, encoding="utf-8")
    scene = SCENE.replace('"ndt13.urdf"', '"arm.urdf"')
    if n != 13:
        scene = re.sub(r"^q0 = .*$", f"q0 = [{', '.join(['0.0'] * n)}]", scene, flags=re.M)
        scene = re.sub(r"^points = .*$", 'points = ["l1", "l2"]', scene, flags=re.M)
        scene = scene.replace('rail = "rail"', "")
    (folder / "arm.toml").write_text(scene, encoding="utf-8")

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))

    argv = ["plan", str(folder / "arm.toml"), "--backend", "pinv", "-o", str(folder / "o.npz")]
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "dvqp", *argv],
        capture_output=True,
        text=True,
        preexec_fn=cap,
        cwd=ROOT,
        timeout=300,
    )
    return done, time.perf_counter() - start


def test_a_link_with_two_parents_is_refused_in_one_line_not_a_crash(tmp_path: Path) -> None:
    done, _ = capped_plan(tmp_path, ARM.replace("</robot>", f"{CYCLE}\n</robot>"), 13)
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert done.stderr == (
        f"dvqp: {tmp_path / 'arm.toml'}: robot.urdf: {tmp_path / 'arm.urdf'}: joint 'cyc': link "
        "'link2' already has parent joint 'joint2' (a link has at most one parent)\n"
    )
    assert not (tmp_path / "o.npz").exists()


def test_a_thousand_joint_arm_is_refused_quickly_within_bounded_memory(tmp_path: Path) -> None:
    done, seconds = capped_plan(tmp_path, chain(1000), 1000)
    assert done.returncode == 2, (done.returncode, done.stderr)
    assert done.stderr == (
        f"dvqp: {tmp_path / 'arm.toml'}: robot.urdf: {tmp_path / 'arm.urdf'}: 1002 links: dvqp "
        "takes at most 256\n"
    )
    assert seconds < 60.0


def write(folder: Path, text: str | bytes) -> Path:
    path = folder / "arm.urdf"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text, encoding="utf-8")
    return path


BOMB = (
    '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY e0 "aaaaaaaaaa">'
    + "".join(f'<!ENTITY e{i + 1} "{f"&e{i};" * 10}">' for i in range(8))
    + ']>\n<robot name="&e8;"><link name="base"/></robot>'
)
"""A billion laughs: the robot's name would expand to 10**9 characters."""
EXTERNAL = '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;"/>'
REFUSED = [
    (
        "two parents",
        ARM.replace("</robot>", f"{CYCLE}</robot>"),
        "joint 'cyc': link 'link2' already has parent joint 'joint2'",
    ),
    (
        "a cycle",
        ARM.replace(
            '<parent link="base"/><child link="link1"/>',
            '<parent link="probe"/><child link="link1"/>',
        ),
        "the joints 'joint1', 'probe_fixed', 'joint13', 'joint12', 'joint11', 'joint10', "
        "... form a cycle: the links must form a tree",
    ),
    (
        "a self loop",
        ARM.replace(
            '<parent link="link1"/><child link="link2"/>',
            '<parent link="link2"/><child link="link2"/>',
        ),
        "the joints 'joint2' form a cycle",
    ),
    (
        "a missing link",
        ARM.replace(
            '<parent link="link4"/><child link="point1"/>',
            '<parent link="link44"/><child link="point1"/>',
        ),
        "joint 'point1_fixed': parent link 'link44' is not a link of the file",
    ),
    (
        "a joint with two parent elements",
        ARM.replace('<parent link="link1"/>', '<parent link="link1"/><parent link="base"/>'),
        "joint 'joint2' has 2 <parent> elements, not one",
    ),
    (
        "a joint with no child",
        ARM.replace('<child link="link3"/>', ""),
        "joint 'joint3' has 0 <child> elements, not one",
    ),
    (
        "two roots",
        ARM.replace('<link name="base"/>', '<link name="base"/><link name="island"/>'),
        "2 links have no parent joint ('base', 'island'): the links must form one tree",
    ),
    ("an entity bomb", BOMB, "a DOCTYPE (DTD, entities) is not allowed in a URDF file"),
    ("an external entity", EXTERNAL, "a DOCTYPE (DTD, entities) is not allowed"),
    (
        "NaN in an origin",
        ARM.replace(
            'xyz="0 0 0.334" rpy="-1.5707963267948966 0 0"/><axis',
            'xyz="0 nan 0.334" rpy="-1.5707963267948966 0 0"/><axis',
        ),
        "joint 'joint3': origin xyz = '0 nan 0.334': expected 3 finite numbers",
    ),
    (
        "an overflowing rpy",
        ARM.replace('rpy="1.5707963267948966 0 0"', 'rpy="1e999 0 0"', 1),
        "joint 'joint2': origin rpy = '1e999 0 0': expected 3 finite numbers",
    ),
    (
        "two numbers for three",
        ARM.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 1"/>', 1),
        "joint 'joint1': axis xyz = '0 1': expected 3 finite numbers",
    ),
    (
        "a zero axis",
        ARM.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1),
        "joint 'joint1': axis xyz '0 0 0' has no direction",
    ),
    (
        "a limit without velocity",
        ARM.replace(' effort="10" velocity="1.5"/>', ' effort="1"/>', 1),
        "joint 'joint1': <limit> has no velocity",
    ),
    (
        "a revolute joint without limit",
        chain(2).replace('<limit lower="-1" upper="1" effort="1" velocity="1"/>', "", 1),
        "joint 'j1' is revolute but has no <limit>",
    ),
    (
        "crossed limits",
        chain(2).replace('lower="-1" upper="1"', 'lower="1" upper="-1"', 1),
        "joint 'j1': limit lower 1 > upper -1",
    ),
    (
        "a planar joint",
        ARM.replace('name="joint3" type="revolute"', 'name="joint3" type="planar"'),
        "joint 'joint3' has type 'planar': dvqp takes only revolute, continuous, prismatic and "
        "fixed joints",
    ),
    (
        "a control character in a name",
        ARM.replace('name="link3"', 'name="link&#127;3"'),
        "link number 5: the name 'link\\x7f3' is not 200 printable characters or fewer",
    ),
    (
        "a line break in a name",
        ARM.replace('name="joint4"', 'name="joint&#10;4"'),
        "joint number 5: the name 'joint\\n4' is not 200 printable",
    ),
    ("an empty name", ARM.replace('name="link3"', 'name=""', 1), "link number 5 has no name"),
    (
        "two links of one name",
        ARM.replace('<link name="point1"/>', '<link name="link4"/>'),
        "two links are named 'link4'",
    ),
    (
        "too many actuated joints",
        chain(65),
        "65 revolute, continuous and prismatic joints: dvqp takes at most 64",
    ),
    (
        "no joint that moves",
        '<robot name="r"><link name="a"/></robot>',
        "no revolute, continuous or prismatic joint: nothing moves",
    ),
    ("another root element", "<urdf><robot/></urdf>", "the root element is <urdf>, not <robot>"),
    ("not XML", "<robot", "not well-formed XML: unclosed token: line 1, column 0"),
    (
        "deep nesting",
        ARM.replace(
            '<link name="base"/>', '<link name="base">' + "<a>" * 20000 + "</a>" * 20000 + "</link>"
        ),
        "elements nested more than 16 deep",
    ),
    (
        "not UTF-8",
        ARM.encode("utf-8").replace(b'name="base"', b'name="b\xe4se"'),
        "not UTF-8 text (byte ",
    ),
    (
        "a huge file",
        ARM.replace("</robot>", "<!--" + "x" * MAX_BYTES + "--></robot>"),
        "larger than 1 MiB: not a robot description",
    ),
]


@pytest.mark.parametrize(("text", "reason"), [c[1:] for c in REFUSED], ids=[c[0] for c in REFUSED])
def test_a_bad_robot_file_is_refused_before_the_parser_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, text: str | bytes, reason: str
) -> None:
    path = write(tmp_path, text)

    def parser(*args: object) -> None:  # pragma: no cover - the checks must come first
        raise AssertionError("Pinocchio's parser saw a file the checks refuse")

    monkeypatch.setattr("dvqp.kinematics.urdf.pin.buildModelFromXML", parser)
    with pytest.raises(RobotFileError) as info:
        Robot.from_urdf(path, ["link4", "link6"], "probe")
    assert str(info.value).startswith(f"{path}: {reason}"), str(info.value)
    assert "\n" not in str(info.value) and info.value.path == str(path)


def test_the_bundled_arm_and_a_64_joint_chain_pass_the_checks(tmp_path: Path) -> None:
    assert read_urdf(ROOT / "scenes" / "ndt13.urdf").actuated == 13
    path = write(tmp_path, chain(64, "continuous"))
    assert read_urdf(path).actuated == 64
    robot = Robot.from_urdf(path, ["l1", "l2"], "probe")
    assert robot.n == 64 and robot.model.njoints == 65


def test_a_scene_checks_its_per_joint_arrays_before_the_arm_is_built(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "arm.urdf").write_text(chain(3), encoding="utf-8")
    base = SCENE.replace('"ndt13.urdf"', '"arm.urdf"').replace('rail = "rail"', "")
    base = re.sub(r"^points = .*$", 'points = ["l1", "l2"]', base, flags=re.M)
    base = re.sub(r"^q0 = .*$", "q0 = [0.0, 0.0, 0.0]", base, flags=re.M)

    def build(*args: object, **kwargs: object) -> None:  # pragma: no cover - must not run
        raise AssertionError("the arm was built before its per-joint arrays were checked")

    monkeypatch.setattr(Robot, "from_urdf", build)
    cases = [
        (
            "q0 = [0.0, 0.0, 0.0]",
            f"q0 = [{', '.join(['0.0'] * 13)}]",
            "q0",
            "an array of 3 numbers, got 13 values",
        ),
        (
            "qdd_max = 10.0",
            "qdd_max = [1.0, 1.0]",
            "qdd_max",
            "a number or an array of 3 numbers, got 2 values",
        ),
        (
            "[robot]",
            "[robot]\nweights = [1.0]",
            "weights",
            "a number or an array of 3 numbers, got 1 values",
        ),
        (
            "[robot]",
            "[robot]\nq_max = [1.0, 1.0, 1.0, 1.0]",
            "q_max",
            "a number or an array of 3 numbers, got 4 values",
        ),
    ]
    for old, new, key, reason in cases:
        (tmp_path / "arm.toml").write_text(base.replace(old, new), encoding="utf-8")
        with pytest.raises(SceneError) as info:
            load_scene(tmp_path / "arm.toml")
        assert str(info.value) == f"{tmp_path / 'arm.toml'}: robot.{key}: expected {reason}"
