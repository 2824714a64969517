"""The developed view zooms to the arc of the arm and the obstacles; l is periodic."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from dvqp import Obstacle, Trajectory
from dvqp.cli import main
from dvqp.cli.drawing import arc_extent, make_view
from tests.runs import run, scene

pytest.importorskip("matplotlib")

RADIUS = 0.254
PERIOD = 2 * np.pi * RADIUS
FULL = (-1.12 * np.pi * RADIUS, 1.12 * np.pi * RADIUS)


def occupied(traj: Trajectory, obstacles: list) -> np.ndarray:
    """Every l the arm (rail point, body points, tool) or an obstacle's outline takes."""
    rings = [o.outline()[:, 0] for o in obstacles]
    arm = [traj.rail[:, 0], traj.points[..., 0].ravel(), traj.tool[:, 0]]
    return np.concatenate([*arm, *(r for r in rings if not np.isnan(r).all())])


def inside(l: np.ndarray, lo: float, hi: float) -> bool:
    """Every l, moved by whole periods, lies in [lo, hi]."""
    return bool(np.all((l - lo) % PERIOD <= hi - lo + 1e-12))


def shifted(traj: Trajectory, obstacles: list, by: float) -> tuple[Trajectory, list]:
    """The run and its circles moved by ``by`` in l (rail l wrapped, as recorded)."""
    points, tool, rail = traj.points.copy(), traj.tool.copy(), traj.rail.copy()
    points[..., 0] += by
    tool[:, 0] += by
    rail[:, 0] = (rail[:, 0] + by + 0.5 * PERIOD) % PERIOD - 0.5 * PERIOD
    moved = [Obstacle(np.add(o.center, (by, 0.0)), o.radius, o.weight) for o in obstacles]
    return dataclasses.replace(traj, points=points, tool=tool, rail=rail), moved


@pytest.fixture(scope="module")
def paper() -> tuple[Trajectory, list]:
    return run("paper-two-inlets", "daqp"), list(scene("paper-two-inlets").obstacles)


def test_the_view_spans_the_arm_and_the_obstacles_with_a_margin(paper: tuple) -> None:
    traj, obstacles = paper
    lo, hi = make_view(traj, obstacles).limits[:2]
    assert inside(occupied(traj, obstacles), lo + 0.03, hi - 0.03)  # 3 cm margin at least
    assert hi - lo < 0.6 < FULL[1] - FULL[0]
    assert make_view(traj, obstacles, full=True).limits[:2] == pytest.approx(FULL)


@pytest.mark.parametrize("by", [np.pi * RADIUS - 0.1, -np.pi * RADIUS - 0.05, PERIOD])
def test_the_zoom_moves_with_the_scene_across_the_seam(paper: tuple, by: float) -> None:
    """Moved round the pipe, the arc is the same length and holds everything; its middle is
    wrapped into (−πR, πR], its ends may pass the seam."""
    traj, obstacles = paper
    lo, hi = arc_extent(traj, obstacles, RADIUS)
    moved, circles = shifted(traj, obstacles, by)
    mlo, mhi = arc_extent(moved, circles, RADIUS)
    assert mhi - mlo == pytest.approx(hi - lo, abs=1e-9)
    assert (mlo - lo - by) % PERIOD == pytest.approx(0.0, abs=1e-9) or (
        (mlo - lo - by) % PERIOD == pytest.approx(PERIOD, abs=1e-9)
    )
    assert -np.pi * RADIUS < 0.5 * (mlo + mhi) <= np.pi * RADIUS
    assert inside(occupied(moved, circles), mlo, mhi)


@pytest.mark.parametrize(("at", "by"), [(np.pi * RADIUS, np.pi * RADIUS - 0.35), (0.0, 0.12)])
def test_an_obstacle_across_a_period_is_one_stretch(at: float, by: float) -> None:
    """A circle on the seam (or on l = 0, where l modulo 2πR starts again) with the arm
    beside it: the arc holds both, the empty stretch is not taken from under the circle."""
    traj = run("paper-two-inlets", "daqp")
    circle = Obstacle([at, 0.3], 0.1, 1.0)
    moved, _ = shifted(traj, [], by)
    lo, hi = arc_extent(moved, [circle], RADIUS)
    assert inside(occupied(moved, [circle]), lo, hi)
    l = occupied(moved, [circle])
    l = at + (l - at + 0.5 * PERIOD) % PERIOD - 0.5 * PERIOD  # near the circle: no seam between
    assert hi - lo == pytest.approx(1.16 * np.ptp(l) + 0.06)  # the stretch, 8 % and 3 cm a side
    assert hi - lo < 0.8  # the arm spans ~0.4 m: not round the back of the pipe


def test_what_passes_2pir_hides_the_stretches_it_covers_again() -> None:
    """A circle on l = 0 (its outline from 2πR − 0.1 past 2πR to 0.1) hides a small one at
    l = 0.05: the longest empty stretch is the 0.415 m round the back, not the 0.43 m from the
    small circle to the arm, of which 0.03 m is under the first."""
    traj = run("paper-two-inlets", "daqp")
    arm = occupied(traj, [])
    moved, _ = shifted(traj, [], 0.5 - arm.min())  # the arm from l = 0.5 m
    top = occupied(moved, []).max()
    end = PERIOD - 0.1 - 0.415  # a third circle from the arm's end to here
    shapes = [
        Obstacle([0.0, 0.3], 0.1, 1.0),
        Obstacle([0.05, 0.3], 0.02, 1.0),
        Obstacle([0.5 * (top - 0.02 + end), 0.3], 0.5 * (end - top + 0.02), 1.0),
    ]
    lo, hi = arc_extent(moved, shapes, RADIUS)
    assert hi - lo == pytest.approx(1.16 * (end + 0.1) + 0.06, abs=1e-3)
    assert inside(occupied(moved, shapes), lo, hi)


def test_a_run_all_round_the_pipe_is_drawn_whole() -> None:
    traj = run("weld-circumference", "daqp")
    assert arc_extent(traj, [], RADIUS) is None
    assert make_view(traj).limits[:2] == pytest.approx(FULL)


def test_plot_full_draws_the_whole_circumference(tmp_path: Path) -> None:
    from PIL import Image

    npz = tmp_path / "run.npz"
    run("paper-two-inlets", "daqp").save(npz)
    sizes = {}
    for name, extra in (("zoom", []), ("full", ["--full"])):
        png = tmp_path / f"{name}.png"
        assert main(["plot", str(npz), "-o", str(png), *extra]) == 0
        with Image.open(png) as im:
            sizes[name] = im.size
    assert sizes["zoom"][1] > sizes["full"][1]  # the zoomed view is taller: a narrower arc
