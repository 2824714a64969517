"""The whole arm as it is in metal: the runs that broke an unmodelled part, as scene files.

Each QP run is checked by the independent checker (``tests/safety.py``: Pinocchio's frames,
every link the real 3-D segment sampled, configurations between the samples too), and ends at
rest within ``qdd_max``; the baseline, which keeps no limit, fails naming the part.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import dvqp
from dvqp.cli import main
from dvqp.limits import ProbeHeight, SurfaceHeight
from tests import safety
from tests.motion.test_rest import assert_ends_at_rest
from tests.runs import QP

HERE = Path(__file__).resolve().parents[1] / "data" / "scenes"


def scene(name: str) -> dvqp.Scene:
    return dvqp.load_scene(HERE / f"{name}.toml")


def holds_and_rests(s: dvqp.Scene, traj: dvqp.Trajectory) -> dict[str, float]:
    """Check the run succeeded and stopped; return its worst breaches (m) over the samples
    and two configurations between each two."""
    dvqp.check_run(s, traj)  # raises on a broken limit or a failed step
    assert_ends_at_rest(s, traj)
    return safety.worst_breach(s, safety.between(traj.q, 2))


@pytest.mark.parametrize("backend", QP)
def test_the_qp_holds_every_link_chord_at_the_floor(backend: str) -> None:
    s = scene("chords-to-the-wall")
    assert next(x for x in s.limits if isinstance(x, SurfaceHeight)).min_height == 0.0
    traj = dvqp.plan(s, backend)
    breach = holds_and_rests(s, traj)
    assert breach["height"] <= 1e-4  # the lowest point of every real link, not only the points
    assert breach["height"] > -1e-3  # the floor is reached: the chords rest on it
    assert breach["clearance"] <= 1e-4 and breach["probe height"] <= 1e-4


def test_the_baseline_drives_the_link_chords_into_the_wall() -> None:
    s = scene("chords-to-the-wall")
    traj = dvqp.plan(s, "pinv")
    assert safety.worst_breach(s, traj.q[::10])["height"] > 0.02
    with pytest.raises(dvqp.DvqpError, match=r"link\d/height"):
        dvqp.check_run(s, traj)


@pytest.mark.parametrize("backend", QP)
def test_the_qp_keeps_the_probe_holder_out_of_the_wall(backend: str) -> None:
    s = scene("holder-to-the-wall")
    assert any(isinstance(x, ProbeHeight) for x in s.limits)
    traj = dvqp.plan(s, backend)
    breach = holds_and_rests(s, traj)
    assert -1e-3 < breach["probe height"] <= 1e-4  # the holder, the whole of it, on the wall
    assert breach["height"] <= 1e-4 and breach["clearance"] <= 1e-4


def test_the_baseline_drives_the_probe_holder_into_the_wall() -> None:
    s = scene("holder-to-the-wall")
    traj = dvqp.plan(s, "pinv")
    assert safety.worst_breach(s, traj.q[::10])["probe height"] > 0.02
    with pytest.raises(dvqp.DvqpError, match=r"(holder|link\d|probe)/height"):
        dvqp.check_run(s, traj)


def test_a_floor_above_the_rail_point_is_refused_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, out = HERE / "floor-above-the-rail.toml", tmp_path / "x.npz"
    assert main(["plan", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dvqp: {path}: constraints.min_height: 0.1 m is above the rail")
    assert "h = 0.08 m" in err and err.count("\n") == 1 and not out.exists()
