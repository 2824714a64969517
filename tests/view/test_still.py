"""``dvqp plot --3d``: a PNG of the 3-D view, checked by its pixels (the pipe's blue and the
arm's orange), and its refusals (one line, exit 2, nothing written)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from dvqp.cli.main import main
from tests import runs

pytest.importorskip("matplotlib")


def colour_counts(png: Path) -> dict[str, int]:
    """Pixels of the pipe's blue, the arm's orange and the margin's red (any shading)."""
    from PIL import Image

    rgb = np.asarray(Image.open(png).convert("RGB")).astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return {
        "pipe": int(np.sum((b > r + 60) & (b > g + 30) & (g > r))),
        "arm": int(np.sum((r > 200) & (g > 100) & (g < 170) & (b < 60))),
        "margin": int(np.sum((r > 180) & (g < 60) & (b < 60))),
    }


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("still")
    runs.run("paper-two-inlets", "pinv").save(folder / "pinv.npz")
    return folder


def test_plot_3d_writes_a_png_showing_the_pipe_and_the_arm(saved: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    png = saved / "pinv-3d.png"
    assert main(["plot", str(saved / "pinv.npz"), "-o", str(png), "--3d"]) == 0
    assert capsys.readouterr().out == f"wrote {png}\n"
    counts = colour_counts(png)
    assert counts["pipe"] > 100_000  # the pipe fills much of the picture
    assert counts["arm"] > 1_000  # the arm's links
    assert counts["margin"] > 200  # the baseline's links at the lower inlet's margin


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--gif"], "--3d takes neither --limits, --gif nor --full"),
        (["--full"], "--3d takes neither --limits, --gif nor --full"),
    ],
)
def test_plot_3d_refuses_other_figure_options(saved: Path, capsys, extra, message) -> None:  # type: ignore[no-untyped-def]
    png = saved / "refused.png"
    assert main(["plot", str(saved / "pinv.npz"), "-o", str(png), "--3d", *extra]) == 2
    assert capsys.readouterr().err == f"dvqp: {message}\n"
    assert not png.exists()


def test_plot_3d_of_a_run_without_its_scene_asks_for_it(saved: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    bare = saved / "bare.npz"
    dataclasses.replace(runs.run("paper-two-inlets", "pinv"), scene_text="").save(bare)
    png = saved / "bare.png"
    assert main(["plot", str(bare), "-o", str(png), "--3d"]) == 2
    assert capsys.readouterr().err == f"dvqp: {bare}: no stored scene: give the run's --scene\n"
    assert not png.exists()
    scene = str(runs.SCENES / "paper-two-inlets.toml")
    assert main(["plot", str(bare), "-o", str(png), "--3d", "--scene", scene]) == 0
    assert colour_counts(png)["arm"] > 1_000


def test_plot_3d_refuses_a_scene_the_run_is_not_of(saved: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    text = (runs.SCENES / "paper-two-inlets.toml").read_text()
    wider = saved / "wider.toml"
    wider.write_text(text.replace("radius = 0.254", "radius = 0.3", 1))
    png = saved / "wider.png"
    assert (
        main(["plot", str(saved / "pinv.npz"), "-o", str(png), "--3d", "--scene", str(wider)]) == 2
    )
    assert capsys.readouterr().err == (
        f"dvqp: {saved / 'pinv.npz'}: not a run of {wider}: its "
        "pipe radius is 0.254 m, the scene's 0.3 m\n"
    )
    assert not png.exists()
