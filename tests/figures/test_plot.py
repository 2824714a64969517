"""Figures and animations of trajectories: files, formats, atomic writes, no display needed."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dvqp import DvqpError, Obstacle, ParameterError, Trajectory, load_scene, plan
from dvqp.cli import drawing, plot
from tests.common import LINK_LENGTHS, PIPE_RADIUS, Q0

pytest.importorskip("matplotlib")

HALF = np.pi * PIPE_RADIUS
ROOT = Path(__file__).resolve().parents[2]
PNG = b"\x89PNG\r\n\x1a\n"
SCENE = """
name = "{name}"
[pipe]
radius = {radius}
[robot]
model = "ndt13"
link_lengths = {links}
q0 = {q0}
[objective]
orbital_level = 0.08
[motion]
dt = 0.01
[[motion.jog]]
duration = {duration}
velocity = {velocity}
"""


def planned(
    folder: Path, name: str, q0: list[float], duration: float, velocity: list[float]
) -> Trajectory:
    """A JOG scene of the paper's arm, run with the pseudoinverse baseline."""
    text = SCENE.format(
        name=name,
        radius=PIPE_RADIUS,
        links=LINK_LENGTHS,
        q0=q0,
        duration=duration,
        velocity=velocity,
    )
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return plan(load_scene(path), "pinv")


@pytest.fixture(scope="module")
def obstacles() -> list[Obstacle]:
    return [Obstacle([0.2, 0.22], 0.04, 5.0), Obstacle([HALF - 0.02, 0.18], 0.05, 5.0)]


@pytest.fixture(scope="module")
def plain(tmp_path_factory: pytest.TempPathFactory) -> Trajectory:
    return planned(tmp_path_factory.mktemp("plain"), "plain", Q0, 0.4, [0.05, 0.0, 0.0, 0.1])


@pytest.fixture(scope="module")
def seam(tmp_path_factory: pytest.TempPathFactory) -> Trajectory:
    """The carriage joint turned so the tool starts at l = 0.75 m and crosses l = πR."""
    q0 = list(Q0)
    q0[0] += (0.75 - 0.2973) / PIPE_RADIUS
    traj = planned(tmp_path_factory.mktemp("seam"), "seam", q0, 0.6, [0.2, 0.0, 0.0, 0.0])
    assert traj.tool[0, 0] < HALF < traj.tool[-1, 0], "the tool must cross the seam"
    assert traj.points[-1, -1, 0] > HALF, "the last body point must cross the seam"
    return traj


def _no_display(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.delenv("MPLBACKEND", raising=False)


@pytest.mark.parametrize("run", ["plain", "seam"])
def test_png_is_written_without_a_display(
    run: str,
    request: pytest.FixtureRequest,
    obstacles: list[Obstacle],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _no_display(monkeypatch)
    traj = request.getfixturevalue(run)
    target = tmp_path / "run.png"
    out = plot.plot_trajectory(
        traj, target, obstacles=obstacles, orbital_level=0.08, weld_z=0.35, instants=5
    )
    assert out == target
    data = target.read_bytes()
    assert data.startswith(PNG)
    assert len(data) > 30_000
    assert os.listdir(tmp_path) == ["run.png"], "a temporary file was left behind"
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask, "not the mode of a plain new file"
    from PIL import Image

    with Image.open(target) as im:
        assert im.width > 1000 and im.height > 700


def test_svg_and_pdf_by_suffix(plain: Trajectory, tmp_path: Path) -> None:
    svg = plot.plot_trajectory(plain, tmp_path / "a.SVG", orbital_level=0.08)
    pdf = plot.plot_trajectory(plain, tmp_path / "a.pdf", instants=1)
    assert b"<svg" in svg.read_bytes()[:2000]
    assert pdf.read_bytes().startswith(b"%PDF")


@pytest.mark.parametrize("run", ["plain", "seam"])
def test_gif_has_several_frames(
    run: str,
    request: pytest.FixtureRequest,
    obstacles: list[Obstacle],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    _no_display(monkeypatch)
    target = tmp_path / "run.gif"
    plot.animate_trajectory(
        request.getfixturevalue(run), target, obstacles=obstacles, weld_z=0.35, fps=10, max_frames=6
    )
    assert target.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    from PIL import Image

    with Image.open(target) as im:
        assert 1 < im.n_frames <= 6
    assert os.listdir(tmp_path) == ["run.gif"]


def test_missing_folder_raises_and_writes_nothing(plain: Trajectory, tmp_path: Path) -> None:
    with pytest.raises(ParameterError, match="no such directory"):
        plot.plot_trajectory(plain, tmp_path / "missing" / "a.png")
    with pytest.raises(ParameterError, match="no such directory"):
        plot.animate_trajectory(plain, tmp_path / "missing" / "a.gif")
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("name", ["a.jpg", "a", "a.png.tmp"])
def test_unknown_suffix_is_refused(plain: Trajectory, tmp_path: Path, name: str) -> None:
    with pytest.raises(ParameterError, match=r"unknown format .*\.png, \.svg, \.pdf"):
        plot.plot_trajectory(plain, tmp_path / name)
    with pytest.raises(ParameterError, match=r"unknown format .*\.gif"):
        plot.animate_trajectory(plain, tmp_path / "a.png")
    assert os.listdir(tmp_path) == []


def test_a_failing_write_keeps_the_old_file_and_no_temporary(
    plain: Trajectory, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from matplotlib.figure import Figure

    target = tmp_path / "a.png"
    target.write_bytes(b"old")

    def broken(self: Figure, fname: str, **kw: object) -> None:
        Path(fname).write_bytes(b"partial")
        raise RuntimeError("disk full")

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        plot.plot_trajectory(plain, target)
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["a.png"]


def test_bad_arguments_raise_parameter_errors(plain: Trajectory, tmp_path: Path) -> None:
    png, gif = tmp_path / "a.png", tmp_path / "a.gif"
    with pytest.raises(ParameterError, match="instants"):
        plot.plot_trajectory(plain, png, instants=0)
    with pytest.raises(ParameterError, match="orbital_level"):
        plot.plot_trajectory(plain, png, orbital_level=float("nan"))
    with pytest.raises(ParameterError, match="weld_z"):
        plot.plot_trajectory(plain, png, weld_z="0.3")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="min_height"):
        plot.plot_trajectory(plain, png, min_height=float("inf"))
    with pytest.raises(ParameterError, match="pipe_radius"):
        plot.plot_trajectory(dataclasses.replace(plain, pipe_radius=0.0), png)
    with pytest.raises(ParameterError, match="fps"):
        plot.animate_trajectory(plain, gif, fps=0)
    with pytest.raises(ParameterError, match="max_frames"):
        plot.animate_trajectory(plain, gif, max_frames=1)
    assert os.listdir(tmp_path) == []


def test_the_heights_panel_draws_the_lowest_link_chord_the_holder_and_min_height(
    plain: Trajectory,
) -> None:
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    plot._draw_heights(ax, drawing.make_view(plain, orbital_level=0.08, min_height=0.02))
    lines = {line.get_label(): line for line in ax.get_lines()}
    np.testing.assert_array_equal(lines["lowest link chord"].get_xdata(), plain.t)
    np.testing.assert_array_equal(lines["lowest link chord"].get_ydata(), plain.link_height)
    np.testing.assert_array_equal(lines["holder, lowest"].get_ydata(), plain.holder_height)
    assert list(lines["min_height = 0.02 m"].get_ydata()) == [0.02, 0.02]
    assert (plain.link_height < plain.points[:, :, 2].min(axis=1)).any()  # a chord dips
    # a file written before the heights were recorded: drawn without them
    old = dataclasses.replace(plain, link_height=np.zeros(0), holder_height=np.zeros(0))
    ax = Figure().add_subplot()
    plot._draw_heights(ax, drawing.make_view(old, orbital_level=0.08))
    assert [line.get_label() for line in ax.get_lines()][-2:] == ["tool", "h* = 0.08 m"]


def test_missing_matplotlib_is_a_clear_error(
    plain: Trajectory, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(DvqpError, match=r"pip install 'dvqp\[plot\]'"):
        plot.plot_trajectory(plain, tmp_path / "a.png")
    assert os.listdir(tmp_path) == []


def test_seam_wrapping_of_the_drawn_body(seam: Trajectory) -> None:
    wrapped = drawing.wrap_arc(seam.tool[:, 0], PIPE_RADIUS)
    assert np.all((wrapped > -HALF) & (wrapped <= HALF))
    np.testing.assert_allclose(drawing.wrap_arc(np.array([HALF, -HALF]), PIPE_RADIUS), [HALF, HALF])
    body = drawing.body_at(seam, seam.t.shape[0] - 1)  # last point and tool beyond the seam
    assert -HALF < body[0, 0] <= HALF
    assert np.all(np.abs(np.diff(body[:, 0])) < 0.5 * HALF), "the polyline jumps"
    assert body[-1, 0] > HALF  # drawn continuous, past the seam, plus a copy 2πR to the left


def test_no_pyplot_and_an_unusable_interactive_backend(seam: Trajectory, tmp_path: Path) -> None:
    """In a fresh process: dvqp.cli.plot does not import matplotlib until called, never pyplot."""
    seam.save(tmp_path / "run.npz")
    code = (
        "import sys; import dvqp.cli.plot as p; from dvqp import Trajectory\n"
        "assert 'matplotlib' not in sys.modules\n"
        f"p.plot_trajectory(Trajectory.load({str(tmp_path / 'run.npz')!r}), "
        f"{str(tmp_path / 'out.png')!r})\n"
        "assert 'matplotlib.pyplot' not in sys.modules\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.update(
        MPLBACKEND="TkAgg", PYTHONPATH=os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out.png").read_bytes().startswith(PNG)
