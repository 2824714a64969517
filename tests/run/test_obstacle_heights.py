"""Obstacles with a height in whole runs: the body passes over a band, a pad or a block lower
than it and round (or over) one taller, every guarded part keeping the margin from each solid
as an independent sampling of the real links measures it; the same scenes without heights
are refused as before; bad heights are refused at load."""

from __future__ import annotations

import functools
import re
from pathlib import Path

import numpy as np
import pytest

import dvqp
from dvqp.cli import main
from tests import safety
from tests.run.test_safety import closest_samples, succeeded
from tests.runs import SCENES, run, scene

MARGIN = 0.01
BAND = "support-band"
BACKENDS = tuple(b for b in dvqp.resolution.available_resolvers() if b != "pinv" and ":" not in b)
"""Every installed QP backend (the qpsolvers-wrapped twins of the native ones left out)."""


def text(name: str) -> str:
    return (SCENES / f"{name}.toml").read_text(encoding="utf-8")


def without_heights(source: str) -> str:
    return re.sub(r"(?m)^height = .*\n", "", source)


def true_clearances(s: dvqp.Scene, traj: dvqp.Trajectory) -> tuple[float, float]:
    """The least true clearance (independent sampling, ``tests/safety.py``) over every 50th
    sample and the 12 samples of least reported clearance, and the largest amount by which a
    reported clearance is above the true one there (≤ 0: never above)."""
    samples = closest_samples(traj.min_clearance)
    true = np.array([safety.clearances(s, traj.q[k])[0] for k in samples])
    return float(true.min()), float((traj.min_clearance[samples] - true).max())


@functools.cache
def band_scene(height: float | None) -> dvqp.Scene:
    """The support-band scene with the band's height changed (None: unbounded) and no pad."""
    source = text(BAND).replace("height = 0.025", f"height = {height}" if height else "")
    start, end = source.index("[[obstacles]]          # a pad"), source.index("[constraints]")
    return dvqp.scenes.loads(source[:start] + source[end:], f"band-{height}.toml")


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_body_passes_over_the_support_band_and_the_pad_on_every_backend(
    backend: str,
) -> None:
    s, traj = scene(BAND), run(BAND, backend)
    assert {o.bounded for o in s.obstacles} == {True}
    assert succeeded(s, traj)
    assert traj.min_clearance.min() >= MARGIN - 1e-4
    band = s.obstacles[0]
    # on every sample a body link crosses the band (its ends either side of it), so with the
    # margin kept it passes over the band's top
    z = np.concatenate([traj.rail[:, None, 1], traj.points[..., 1]], axis=1)
    crosses = (z[:, :-1] < band.z_min) & (z[:, 1:] > band.z_max)
    assert crosses.any(axis=1).all()


def test_the_reported_clearance_over_a_solid_is_never_above_the_true_one() -> None:
    s, traj = scene(BAND), run(BAND, "daqp")
    true, above = true_clearances(s, traj)
    assert true >= MARGIN - 1e-4 and above <= 1e-9


def test_without_heights_the_band_scene_is_refused_as_a_wall_to_the_sky() -> None:
    s = dvqp.scenes.loads(without_heights(text(BAND)), "support-band-walls.toml")
    assert not any(o.bounded for o in s.obstacles)
    traj = dvqp.plan(s, "daqp")
    with pytest.raises(
        dvqp.DvqpError, match=r"broken from the start by 2\d(\.\d)? mm \(link1/support"
    ):
        dvqp.check_run(s, traj)


@pytest.mark.parametrize("height", [0.01, 0.04, 0.065])
def test_a_band_lower_than_the_body_is_passed_over_with_the_margin(height: float) -> None:
    s = band_scene(height)
    traj = dvqp.plan(s, "daqp")
    assert succeeded(s, traj)
    true, above = true_clearances(s, traj)
    assert true >= MARGIN - 1e-4 and above <= 1e-9
    assert (traj.points[..., 2].min(axis=1) > height + MARGIN - 1e-4).all()  # over it, not in


def test_a_band_as_high_as_the_body_is_refused_at_its_start() -> None:
    s = band_scene(0.075)
    traj = dvqp.plan(s, "daqp")
    with pytest.raises(
        dvqp.DvqpError, match=r"margin: broken from the start by 4\.96 mm \(link1/support\)"
    ):
        dvqp.check_run(s, traj)


BLOCKS = {
    "taller than the body": ("center = [0.17, 0.25]\nradius = 0.075", 0.15),
    "as tall as a link's end": (
        'shape = "polygon"\nvertices = [[0.10, 0.22], [0.16, 0.22], [0.16, 0.28], [0.10, 0.28]]',
        0.15,
    ),
    "lower, under the whole lower arm": (
        'shape = "polygon"\nvertices = [[0.0, 0.15], [0.30, 0.15], [0.30, 0.30], [0.0, 0.30]]',
        0.06,
    ),
    "a stub of an inlet": ('shape = "inlet"\ncenter = [0.17, 0.25]\nradius = 0.075', 0.03),
}


@pytest.mark.parametrize("block", BLOCKS, ids=list(BLOCKS))
def test_a_block_is_kept_at_the_margin_around_or_over(block: str) -> None:
    table, height = BLOCKS[block]
    source = text(BAND)
    start, end = source.index("[[obstacles]]"), source.index("[constraints]")
    obstacle = f'[[obstacles]]\nname = "block"\n{table}\nheight = {height}\nweight = 20.0\n\n'
    s = dvqp.scenes.loads(source[:start] + obstacle + source[end:], "block.toml")
    traj = dvqp.plan(s, "daqp")
    assert succeeded(s, traj)
    true, above = true_clearances(s, traj)
    assert true >= MARGIN - 1e-4 and above <= 1e-9


def test_the_command_line_says_the_body_was_over_the_band(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "band.npz"
    assert main(["plan", str(SCENES / f"{BAND}.toml"), "--backend", "daqp", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "safe to send" in printed and out.exists()
    line = next(x for x in printed.splitlines() if x.startswith("min clearance"))
    assert re.search(r"/support, (over|past its edge)\)", line), line


@pytest.mark.parametrize("value", ["0.0", "-0.025", "nan", '"tall"', "[0.025, 0.03]"])
def test_a_bad_height_is_one_line_naming_the_obstacle_and_nothing_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], value: str
) -> None:
    path, out = tmp_path / "bad.toml", tmp_path / "bad.npz"
    path.write_text(text(BAND).replace("height = 0.025", f"height = {value}"), encoding="utf-8")
    assert main(["plan", str(path), "--backend", "daqp", "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dvqp: {path}: obstacles[0].height: ") and err.count("\n") == 1, err
    assert not out.exists()
