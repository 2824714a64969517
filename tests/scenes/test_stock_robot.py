"""A stock robot description, unedited, plans from a scene: example-robot-data's Franka Panda
(``scenes/robots/panda/panda.urdf``, bundled byte for byte) placed by ``[robot.base]``, its
mimic finger following its master (an 8-value q0: 7 arm joints and one finger), and every
report names its links and frames by the URDF's own names."""

from __future__ import annotations

import hashlib
import re
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

from dvqp import DvqpError, check_run, load_scene
from dvqp.cli.main import main
from dvqp.geometry import proximity
from dvqp.kinematics.state import KinematicState
from dvqp.scenes import loads
from tests.runs import run, scene

ROOT = Path(__file__).resolve().parents[2]
PANDA = ROOT / "scenes" / "robots" / "panda" / "panda.urdf"
SHA256 = "63792d2679f22c4e41cda2c4d9d903644e628970ad0656b9eec8485113941555"
"""example-robot-data 6.0.0's robots/panda_description/urdf/panda.urdf."""
NUMBERED = re.compile(r"\b(point\d+|link\d+|probe|holder|carriage|rail)\b(?=/|\)|$| )")
"""dvqp's own numbering of an arm's parts, as a label (``panda_link4`` is not matched)."""


def test_the_bundled_panda_is_example_robot_datas_file_unedited() -> None:
    data = PANDA.read_bytes()
    assert hashlib.sha256(data).hexdigest() == SHA256
    assert (PANDA.parent / "LICENSE").read_text().lstrip().startswith("Apache License")
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install 'dvqp[robots]')")
    theirs = [f for f in files if str(f).endswith("panda_description/urdf/panda.urdf")]
    assert len(theirs) == 1 and Path(theirs[0].locate()).read_bytes() == data


def test_the_panda_scene_counts_its_independent_joints() -> None:
    s = scene("panda")
    assert s.robot.n == 8 and s.q0.shape == (8,)
    assert s.robot.joint_names == (*(f"panda_joint{i}" for i in range(1, 8)), "panda_finger_joint1")
    assert s.robot.model.njoints - 1 == 9  # the mimic finger is a joint, with no coordinate
    np.testing.assert_allclose(s.robot.q_max[[3, 7]], [-0.0698, 0.04])  # the URDF's own
    state = KinematicState.compute(s.robot, s.q0, s.pipe_radius)
    assert s.robot.base_frame == "panda_link0"  # standing on the pipe: its base is guarded
    assert np.all(state.guarded[:-1, 2] > 0.05)  # placed on the pipe: every part above it,
    assert 0.0 < state.guarded[-1, 2] < 0.05  # the base on its foot, 2 cm above the surface


def test_the_panda_plans_safely_on_every_step_and_holds_its_forearm_at_the_margin() -> None:
    s, traj = scene("panda"), run("panda", "daqp")
    check_run(s, traj)  # raises if a limit was broken or the run failed
    statuses = set(traj.status)
    assert statuses <= {"optimal", "relaxed", "braking"} and traj.n_steps == 682
    assert sum(st == "optimal" for st in traj.status) >= 670
    assert float(np.min(traj.min_clearance)) == pytest.approx(0.01, abs=1e-4)
    worst = int(np.argmin(traj.min_clearance))
    at = KinematicState.compute(s.robot, traj.q[worst], s.pipe_radius)
    _, part, _ = proximity(at, s.obstacles).closest()
    assert part == "panda_link4-panda_link5"  # the forearm
    assert 0 < sum(status == "relaxed" for status in traj.status) <= 12  # README: 5 on DAQP


def test_the_baseline_takes_the_forearm_in_and_breaks_the_acceleration_limit() -> None:
    traj = run("panda", "pinv")
    assert 0.0 < float(np.min(traj.min_clearance)) < 0.01 - 0.003  # README: 3.8 mm in
    assert float(np.abs(traj.qddot).max()) > 20.0  # 28.9 rad/s² against the scene's 10


def test_the_report_names_the_urdfs_links_and_frames(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["plan", str(ROOT / "scenes" / "panda.toml"), "--backend", "pinv"]) == 1
    out = capsys.readouterr().out
    assert "(panda_link4-panda_link5/obstacles[0])" in out
    assert "(panda_link4-panda_link5/panda_link7-panda_hand_tcp)" in out
    assert "BROKEN: panda_link4-panda_link5/obstacles[0] clearance" in out
    labelled = re.findall(r"\(([^)]*/[^)]*)\)|BROKEN: (\S+)", out)
    assert labelled and not any(NUMBERED.search(a or b) for a, b in labelled)


BASE = ("xyz = [0.0, 0.32, 0.0]", "rpy = [-1.5707963267948966, -1.5707963267948966, 0.0]")


@pytest.mark.parametrize(
    ("edits", "message"),
    [
        ([("q0 = [0.0,", "q0 = [0.0, 0.0,")], "robot.q0: expected an array of 8 numbers, got 9"),
        ([(BASE[0], "xyz = [0.0, 0.32]")], "robot.base.xyz: expected an array of 3 numbers"),
        ([(BASE[0], "xyz = [0.0, 1e9, 0.0]")], "robot.base.xyz[1]: must be <= 100 m"),
        ([("rpy = [", "rpz = [")], "robot.base.rpz: unknown key (did you mean 'rpy'?)"),
        ([(BASE[0], "xyz = [0, 0, 0]")], "q0: body point 3 (frame 'panda_link5') starts inside"),
        (
            [(BASE[0], "xyz = [0.0, 0.25, 0.0]")],
            "robot.base: the arm's base (frame 'panda_link0') starts inside the pipe: "
            "h = -0.05 m (50 mm inside the pipe wall)",
        ),
        ([(BASE[0], ""), (BASE[1], "")], "frame 'panda_link2' lies on the pipe axis (rho = 0 m)"),
    ],
)
def test_a_bad_placement_or_q0_is_one_line_naming_the_file_and_field(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    edits: list[tuple[str, str]],
    message: str,
) -> None:
    """The last: without its placement the URDF's base frame is the pipe's, the shoulder on
    the pipe axis (the issue's first try)."""
    text = (ROOT / "scenes" / "panda.toml").read_text(encoding="utf-8")
    for old, new in edits:
        assert old in text
        text = text.replace(old, new, 1)
    (tmp_path / "robots").symlink_to(ROOT / "scenes" / "robots")
    path = tmp_path / "panda.toml"
    path.write_text(text, encoding="utf-8")
    assert main(["plan", str(path), "--backend", "daqp"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dvqp: {path}: ") and message in err and err.count("\n") == 1, err
    with pytest.raises(DvqpError, match=re.escape(message)):
        load_scene(path)


@pytest.mark.parametrize(
    ("height", "inside"),
    [("", "50 mm"), ("height = 0.05", "30 mm"), ("height = 0.01", None)],
    ids=["a wall", "taller than the base", "lower than the base"],
)
def test_an_obstacle_over_the_base_is_refused_unless_the_base_stands_over_it(
    height: str, inside: str | None
) -> None:
    """The base (l, z, h) = (0.4712, 0, 0.02) m never moves: an obstacle's solid round it is
    refused at load, naming the frame; one lower than the base's foot is not."""
    text = (ROOT / "scenes" / "panda.toml").read_text(encoding="utf-8")
    table = f'[[obstacles]]\nname = "clamp"\ncenter = [0.4712, 0.0]\nradius = 0.05\n{height}\n\n'
    at = text.index("[constraints]")
    source = str(ROOT / "scenes" / "panda.toml")
    edited = text[:at] + table + text[at:]
    if inside is None:
        s = loads(edited, source)
        assert s.obstacles[1].height == 0.01
        return
    with pytest.raises(DvqpError) as info:
        loads(edited, source)
    assert str(info.value) == (
        f"{source}: obstacles[1]: covers the arm's base (frame 'panda_link0') at [l, z, h] = "
        f"[0.4712, 0, 0.02] m ({inside} inside the circle), which never moves"
    )
