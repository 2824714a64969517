import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest

from dvqp import Trajectory
from dvqp.errors import DvqpError, ParameterError

R = 0.254


def straddling(n_samples: int = 4) -> Trajectory:
    """A body lying across the seam l = ±πR and moving in +l (steps of 1 mm)."""
    edge = np.pi * R
    body = np.array([edge - 0.02, edge - 0.005, -edge + 0.01])  # wrapped l of 3 points
    drift = 0.001 * np.arange(n_samples)[:, None]
    wrapped = (body[None, :] + drift + edge) % (2 * edge) - edge
    points = np.zeros((n_samples, 3, 3))
    points[:, :, 0] = wrapped
    tool = np.zeros((n_samples, 4))
    tool[:, 0] = (-edge + 0.03 + drift[:, 0] + edge) % (2 * edge) - edge
    n = n_samples - 1
    return Trajectory.from_samples(
        dt=0.01,
        q=np.zeros((n_samples, 2)),
        qdot=np.zeros((n, 2)),
        tool=tool,
        points=points,
        pipe_radius=R,
        w=np.zeros(n_samples),
        min_clearance=np.full(n_samples, np.inf),
        solve_time=np.zeros(n),
        step_time=np.zeros(n),
        task_error=np.zeros(n),
        iterations=np.zeros(n, dtype=np.int64),
        success=np.ones(n, dtype=bool),
        status=["optimal"] * n,
        backend="test",
    )


def test_l_is_continuous_along_the_body_and_in_time_across_the_seam() -> None:
    traj = straddling()
    along_body = np.diff(np.column_stack([traj.points[:, :, 0], traj.tool[:, 0]]), axis=1)
    assert np.abs(along_body).max() < 0.05  # no 2πR jump between neighbours
    np.testing.assert_allclose(np.diff(traj.points[:, :, 0], axis=0), 0.001, atol=1e-12)
    np.testing.assert_allclose(np.diff(traj.tool[:, 0]), 0.001, atol=1e-12)


def test_saved_file_has_the_usual_mode_and_no_temporary_is_left(tmp_path: Path) -> None:
    out = straddling().save(tmp_path / "t.npz")
    umask = os.umask(0)
    os.umask(umask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~umask
    assert [p.name for p in tmp_path.iterdir()] == ["t.npz"]


def test_a_failed_write_keeps_the_old_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    target = tmp_path / "t.csv"
    target.write_text("old")

    def explode(*args: object, **kwargs: object) -> None:
        raise OSError("disk full")

    monkeypatch.setattr(np, "savetxt", explode)
    with pytest.raises(OSError, match="disk full"):
        straddling().save(target)
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["t.csv"]


def test_bad_targets_raise_before_writing(tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match="no such directory"):
        straddling().save(tmp_path / "missing" / "t.npz")
    with pytest.raises(DvqpError, match=r"absent\.npz: cannot read: No such file"):
        Trajectory.load(tmp_path / "absent.npz")


def test_a_pickled_file_is_refused_without_suggesting_to_unpickle_it(tmp_path: Path) -> None:
    bad = tmp_path / "pickled.npz"
    np.savez(bad, t=np.array([object()], dtype=object))
    with pytest.raises(DvqpError) as info:
        Trajectory.load(bad)
    assert "unsafe" not in str(info.value) and "not a dvqp trajectory" in str(info.value)


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04 not really a zip", b"plain text"])
def test_a_corrupt_file_is_a_typed_error(tmp_path: Path, content: bytes) -> None:
    bad = tmp_path / "bad.npz"
    bad.write_bytes(content)
    with pytest.raises(DvqpError, match="not a dvqp trajectory"):
        Trajectory.load(bad)


def test_an_unwritable_folder_is_refused_before_any_work() -> None:
    if not Path("/proc/self").exists():
        pytest.skip("needs /proc")
    with pytest.raises(ParameterError, match="cannot write here"):
        straddling().save("/proc/t.npz")


def test_the_safety_diagnostics_round_trip_and_old_files_still_load(tmp_path: Path) -> None:
    traj = straddling()
    n = traj.t.shape[0]
    full = dataclasses.replace(
        traj,
        probe_clearance=np.linspace(0.02, 0.01, n),
        tilt=np.full(n, 1.2),
        limit_excess=np.array([0.0, 2e-5, 0.0, 0.0]),
        limits_kept=np.ones(n, dtype=bool),
        substeps=np.array([1, 4, 1], dtype=np.int64),
        brake_start=2,
    )
    back = Trajectory.load(full.save(tmp_path / "new.npz"))
    for name in ("probe_clearance", "tilt", "limit_excess", "limits_kept", "substeps"):
        np.testing.assert_array_equal(getattr(back, name), getattr(full, name))
    assert back.brake_start == 2 and back.braking_time == pytest.approx(0.01)  # the last step
    # a file written before 0.2: "dv" for the tool, no diagnostics
    arrays = {
        name: getattr(traj, name)
        for name in (
            "t",
            "q",
            "qdot",
            "points",
            "w",
            "min_clearance",
            "solve_time",
            "step_time",
            "task_error",
            "iterations",
            "success",
            "status",
        )
    }
    old = tmp_path / "old.npz"
    np.savez(old, dv=traj.tool, backend="pinv", pipe_radius=R, scene="", **arrays)
    loaded = Trajectory.load(old)
    np.testing.assert_array_equal(loaded.tool, traj.tool)
    assert loaded.limits_kept.shape == (0,) and loaded.substeps.shape == (0,)
    assert loaded.brake_start == -1 and loaded.braking_time is None  # not known to be stopped


def test_each_levels_residual_and_error_round_trip_and_old_files_have_none(
    tmp_path: Path,
) -> None:
    from tests.runs import run

    traj = run("reach-priorities", "daqp")
    assert traj.level_error.shape == (traj.n_steps, 2)
    assert traj.level_deviation.shape == (traj.t.shape[0], 2, 2)
    again = Trajectory.load(traj.save(tmp_path / "r.npz"))
    assert again.levels == traj.levels == ("tool h, alpha", "tool l, z")
    np.testing.assert_array_equal(again.level_error, traj.level_error)
    np.testing.assert_array_equal(again.level_deviation, traj.level_deviation)
    np.testing.assert_array_equal(again.level_measured, [[True, True], [True, False]])
    with np.load(tmp_path / "r.npz") as data:  # a file written before levels were recorded
        older = {k: data[k] for k in data.files if not k.startswith("level")}
    np.savez(tmp_path / "old.npz", **older)
    old = Trajectory.load(tmp_path / "old.npz")
    assert old.levels == () and old.level_error.shape == (0, 0)
