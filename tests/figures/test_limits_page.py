"""The limits page: each limit's true quantity over a run against its bound, for every bundled
scene; the QP keeps every one, the paper's baseline crosses one."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import numpy as np
import pytest

from dvqp.cli import main
from dvqp.cli.limit_series import Curve, LimitPage, limit_series
from dvqp.cli.plot_limits import plot_limits
from tests.oracles.geometry import twin
from tests.runs import BUNDLED, run, scene

pytest.importorskip("matplotlib")
pytest.importorskip("daqp")

PNG = b"\x89PNG\r\n\x1a\n"


def page_of(name: str, backend: str) -> LimitPage:
    return limit_series(scene(name), run(name, backend))


def curves(page: LimitPage, panel: str) -> dict[str, Curve]:
    return {c.label: c for c in page.curves if c.panel == panel}


def assert_sane_png(path: Path) -> None:
    """A PNG of a sensible size, not blank: mostly white paper, some ink, some red (bounds)."""
    from PIL import Image

    assert path.read_bytes().startswith(PNG)
    with Image.open(path) as im:
        rgb = np.asarray(im.convert("RGB"), dtype=float)
    assert rgb.shape[0] > 600 and rgb.shape[1] > 1000
    white = (rgb > 245).all(axis=2).mean()  # a run relaxed throughout is shaded throughout
    assert 0.25 < white < 0.97, f"{white:.0%} of the page is white"
    red = (rgb[..., 0] > 180) & (rgb[..., 1] < 90) & (rgb[..., 2] < 90)
    assert red.sum() > 200, "no bound line drawn"


@pytest.mark.parametrize("name", BUNDLED)
def test_every_qp_curve_of_every_bundled_scene_stays_on_the_safe_side_of_its_bound(
    name: str, tmp_path: Path
) -> None:
    traj = run(name, "daqp")
    assert traj.start_broken == ()  # so every bound is the scene's own, from the first sample
    page = limit_series(scene(name), traj)
    panels = page.panels
    assert {"height", "joint speed", "joint acceleration"} <= set(panels), panels
    assert ("clearance" in panels) == (len(scene(name).obstacles) > 0)
    for c in page.curves:
        assert c.values.shape == c.t.shape and np.isfinite(c.values).all(), c.label
        assert (c.past <= c.tolerance).all(), (
            f"{c.panel} {c.label}: {c.past.max():.3g} {c.unit} past {c.bound}"
        )
    out = plot_limits(page, tmp_path / f"{name}.png", name)
    assert_sane_png(out)
    assert os.listdir(tmp_path) == [f"{name}.png"]


def test_the_baseline_crosses_its_bounds_on_the_paper_scene() -> None:
    """The README's exit 1 of compare: the pseudoinverse takes the body into the lower inlet's
    margin (and, holding no limit, past q̈_max); the QP on the same commands keeps both."""
    pinv, qp = page_of("paper-two-inlets", "pinv"), page_of("paper-two-inlets", "daqp")
    lower = curves(pinv, "clearance")["obstacles[1]"]
    assert lower.bound == 0.01
    assert lower.past.max() > 0.01  # more than 1 cm past the 1 cm margin: into the inlet
    assert lower.values.min() < 0.0
    crossed = {(c.panel, c.label) for c in pinv.curves if (c.past > c.tolerance).any()}
    assert ("clearance", "obstacles[1]") in crossed
    assert any(panel == "joint acceleration" for panel, _ in crossed)
    assert not any((c.past > c.tolerance).any() for c in qp.curves)
    assert curves(qp, "clearance")["obstacles[1]"].values.min() >= 0.01 - 1e-4


@pytest.mark.parametrize("name", ["paper-two-inlets", "carriage-clamp", "fold"])
def test_the_curves_are_the_quantities_the_run_recorded(name: str) -> None:
    """Per obstacle, their least is the run's recorded minimum clearance (measured with the
    broad phase; here every row exact, to the real links' 10 µm); the other curves are the
    recorded self distance, heights and tilt, and the joints' fractions of their limits."""
    traj, sc = run(name, "daqp"), scene(name)
    page = limit_series(sc, traj)
    if len(sc.obstacles):
        least = np.min([c.values for c in curves(page, "clearance").values()], axis=0)
        assert (least >= traj.min_clearance - 1e-12).all()
        np.testing.assert_allclose(least, traj.min_clearance, rtol=0, atol=1e-5)
    np.testing.assert_allclose(
        curves(page, "self distance")["non-adjacent links"].values,
        traj.self_distance,
        rtol=0,
        atol=1e-12,
    )
    heights = curves(page, "height")
    np.testing.assert_allclose(heights["link chords"].values, traj.link_height, atol=1e-12)
    np.testing.assert_allclose(heights["holder"].values, traj.holder_height, atol=1e-12)
    np.testing.assert_allclose(heights["probe"].values, traj.tool[:, 2], atol=1e-12)
    np.testing.assert_allclose(
        heights["body points"].values, traj.points[:, :, 2].min(axis=1), atol=1e-12
    )
    if "tilt" in page.panels:  # asin(sin θ): the tilt from radial, on either side
        tilt = np.minimum(traj.tilt, np.pi - traj.tilt)
        np.testing.assert_allclose(
            curves(page, "tilt")["probe from radial"].values, tilt, atol=1e-9
        )
    robot = sc.robot
    for i, c in enumerate(curves(page, "joint speed").values()):
        np.testing.assert_allclose(c.values, np.abs(traj.qdot[:, i]) / robot.qd_max[i])
    for label, c in curves(page, "joint position").items():  # bounded joints only
        i = int(label.removeprefix("joint")) - 1
        middle, half = (
            0.5 * (robot.q_max[i] + robot.q_min[i]),
            0.5 * (robot.q_max[i] - robot.q_min[i]),
        )
        np.testing.assert_allclose(
            c.values, np.abs(traj.q[:, i] - middle) / half, rtol=0, atol=1e-12
        )


@pytest.mark.parametrize("name", ["paper-two-inlets", "pipe-rack", "many-obstacles"])
def test_each_obstacle_curve_agrees_with_an_independent_distance(name: str) -> None:
    """tests/oracles/geometry.py's distances (circles, inlets, bands, polygons): a curve (the
    least over the guarded points and real links) is never above the points' own, and within
    the links' bend (< 1 mm on this arm) of the straight DV polyline's (rail point, body
    points, tool), also far from the obstacle, where a run measures only a bound."""
    sc, traj = scene(name), run(name, "daqp")
    page = limit_series(sc, traj)
    period = 2 * np.pi * sc.pipe_radius
    chain = np.concatenate([traj.rail[:, None], traj.points, traj.tool[:, None, :3]], axis=1)
    rows = np.unique(np.linspace(0, chain.shape[0] - 1, 80).astype(int))  # the oracle is slow
    chain = chain[rows, :, :2]
    for j, label in enumerate(sc.obstacles.labels):
        shape = twin(sc.obstacles[j])
        points = shape.point_distance(chain.reshape(-1, 2), period)[0]
        links = shape.segment_distance(
            chain[:, :-1].reshape(-1, 2), chain[:, 1:].reshape(-1, 2), period
        )[0]
        curve = curves(page, "clearance")[label].values[rows]
        assert (curve <= points.reshape(chain.shape[:2]).min(axis=1) + 1e-9).all(), label
        straight = links.reshape(chain.shape[0], -1).min(axis=1)
        assert np.abs(curve - straight).max() < 1e-3, label


def test_marks_are_the_runs_relaxed_braking_split_and_failed_steps() -> None:
    traj = run("joint-limit", "daqp")
    page = limit_series(scene("joint-limit"), traj)
    assert page.marks["relaxed"].shape[0] == int(np.sum(traj.status == "relaxed")) > 0
    np.testing.assert_array_equal(page.marks["relaxed"], traj.t[:-1][traj.status == "relaxed"])
    assert page.marks["failed"].shape[0] == 0
    fold = limit_series(scene("fold"), run("fold", "daqp"))
    assert fold.marks["braking"].shape[0] == int(np.sum(run("fold", "daqp").status == "braking"))
    assert fold.marks["braking"].shape[0] >= 1


def test_plot_limits_cli_writes_the_page_from_the_stored_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    npz, png = tmp_path / "run.npz", tmp_path / "limits.png"
    run("paper-two-inlets", "pinv").save(npz)
    assert main(["plot", str(npz), "-o", str(png), "--limits"]) == 0
    assert capsys.readouterr().out == f"wrote {png}\n"
    assert_sane_png(png)
    for bad in (["--scene", "scenes/fold.toml"], ["--limits", "--gif"], ["--limits", "--full"]):
        assert main(["plot", str(npz), "-o", str(tmp_path / "x.png"), *bad]) == 2
        assert "dvqp: --scene goes with --limits" in capsys.readouterr().err
    wrong = tmp_path / "wrong.npz"  # its stored scene's pipe is not the one it was run in
    dataclasses.replace(run("paper-two-inlets", "pinv"), pipe_radius=0.3).save(wrong)
    assert main(["plot", str(wrong), "-o", str(tmp_path / "x.png"), "--limits"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dvqp: {wrong}: not a run of {wrong} (stored scene): ")
    assert "pipe radius is 0.3 m, the scene's 0.254 m" in err and err.count("\n") == 1
    assert sorted(os.listdir(tmp_path)) == ["limits.png", "run.npz", "wrong.npz"]


def test_plot_limits_against_another_scene_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    npz, png = tmp_path / "run.npz", tmp_path / "limits.png"
    run("paper-two-inlets", "daqp").save(npz)
    same = ["plot", str(npz), "-o", str(png), "--limits", "--scene"]
    assert main([*same, "scenes/paper-two-inlets.toml"]) == 0
    assert "note" not in capsys.readouterr().err  # the scene it was planned from
    assert main([*same, "scenes/paper-inlets.toml"]) == 0  # the same arm: allowed, but said
    err = capsys.readouterr().err
    assert err == (
        f"dvqp: note: {npz} was planned from another scene text than "
        "scenes/paper-inlets.toml: drawn with the latter's arm, obstacles and "
        "limits\n"
    )
