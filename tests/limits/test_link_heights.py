"""The lowest link chord and the probe holder's lowest point: recorded per sample by the
compiled step, saved with the trajectory, reported (``plan``'s summary, ``compare``'s row)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from dvqp import Scene, Trajectory
from dvqp.cli import main
from dvqp.cli.report import format_summary
from dvqp.run.comparison import summarize
from tests import runs
from tests.oracles.limits import chord_low, guarded_links, link_name
from tests.oracles.resolution import frames

RUNS = [("narrow-passage", "daqp"), ("narrow-passage", "pinv")]


def lows(scene: Scene, q: np.ndarray) -> np.ndarray:
    """The lowest height (m) of every guarded link's straight 3-D chord at ``q``, by link
    (body links, the holder at k − 1, the carriage), from Pinocchio's frames and a ternary
    search (not dvqp's closed form)."""
    f = frames(scene.robot, q, scene.pipe_radius)
    ends = guarded_links(f.k, f.rail)
    return np.array([chord_low(f.origins[a], f.origins[b], scene.pipe_radius)[0] for a, b in ends])


@pytest.mark.parametrize(("name", "backend"), RUNS)
def test_recorded_link_and_holder_heights_are_the_chords_lowest_points(
    name: str, backend: str
) -> None:
    scene, traj = runs.scene(name), runs.run(name, backend)
    k = scene.robot.n_points
    assert scene.robot.has_rail  # the carriage link counts among the links
    every = np.array([lows(scene, q) for q in traj.q[::2]])  # every other sample: 281
    body = np.delete(every, k - 1, axis=1)
    np.testing.assert_allclose(traj.link_height[::2], body.min(axis=1), rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(traj.holder_height[::2], every[:, k - 1], rtol=0.0, atol=1e-12)
    # not the points': a chord dips below both its ends (by mm here)
    assert (traj.points[:, :, 2].min(axis=1) - traj.link_height).max() > 1e-3


def test_plan_reports_the_lowest_link_chord_and_the_holder(tmp_path: Path) -> None:
    scene, traj = runs.scene("narrow-passage"), runs.run("narrow-passage", "daqp")
    row = summarize(scene, traj)
    at = int(np.argmin(traj.link_height))
    body = lows(scene, traj.q[at])
    k = scene.robot.n_points
    body[k - 1] = np.inf  # the holder is not a body link
    assert row["lowest_link"] == link_name(int(np.argmin(body)), k) == "link4"
    assert row["min_link_height"] == pytest.approx(0.05, abs=1e-4)  # held at min_height
    assert row["min_link_height"] == traj.link_height.min()
    text = format_summary(scene, traj, row, None)
    want = (
        f"link heights    lowest {traj.link_height.min():+.4f} m (link4), "
        f"holder {traj.holder_height.min():+.4f} m"
    )
    assert [line for line in text.splitlines() if line.startswith("link heights")] == [want]


def test_the_heights_are_saved_and_a_file_without_them_loads_empty(tmp_path: Path) -> None:
    scene, traj = runs.scene("narrow-passage"), runs.run("narrow-passage", "daqp")
    back = Trajectory.load(traj.save(tmp_path / "new.npz"))
    np.testing.assert_array_equal(back.link_height, traj.link_height)
    np.testing.assert_array_equal(back.holder_height, traj.holder_height)
    with np.load(tmp_path / "new.npz") as data:  # as written before the heights were recorded
        arrays = {n: data[n] for n in data.files if n not in ("link_height", "holder_height")}
    np.savez(tmp_path / "old.npz", **arrays)
    old = Trajectory.load(tmp_path / "old.npz")
    assert old.link_height.shape == (0,) and old.holder_height.shape == (0,)
    row = summarize(scene, old)
    assert row["min_link_height"] is None and row["lowest_link"] is None
    assert "link heights" not in format_summary(scene, old, row, None)
    np.testing.assert_array_equal(old.q, traj.q)


def test_plot_draws_the_stored_scenes_min_height(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from dvqp.cli import plot

    drawn: dict[str, object] = {}
    monkeypatch.setattr(plot, "plot_trajectory", lambda traj, out, **kw: drawn.update(kw) or out)
    saved = runs.run("narrow-passage", "pinv").save(tmp_path / "run.npz")
    assert main(["plot", str(saved), "-o", str(tmp_path / "run.png")]) == 0
    assert drawn["min_height"] == 0.05 and drawn["orbital_level"] == 0.08
    assert capsys.readouterr().out.startswith("wrote ")
