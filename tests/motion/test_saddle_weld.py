"""Saddle welds: the offset curve round a branch, its waypoints, the scene keys and a run."""

from __future__ import annotations

import math

import numpy as np
import pytest

import dvqp
from dvqp.errors import ParameterError, SceneError
from dvqp.motion.saddle import CHORD_TOLERANCE, SaddleWeld
from dvqp.scenes.scene import loads
from tests.runs import SCENES, run, scene

R = 0.254


def cylinders_meet(center, rho, theta):  # type: ignore[no-untyped-def]
    """Oracle: the 3-D points where a tube of radius ``rho`` along the radial line through the
    DV point ``center`` meets the pipe (x² + y² = R²), mapped to (l, z) by atan2."""
    phi0 = center[0] / R
    axis = np.array([math.cos(phi0), math.sin(phi0), 0.0])
    across = np.array([-math.sin(phi0), math.cos(phi0), 0.0])
    out = []
    for t in theta:
        a, b = rho * math.cos(t), rho * math.sin(t)
        p = math.sqrt(R * R - a * a) * axis + a * across + np.array([0.0, 0.0, center[1] + b])
        out.append([R * math.atan2(p[1], p[0]), p[2]])
    return np.array(out)


def wrap_l(dl):  # type: ignore[no-untyped-def]
    return np.mod(dl + math.pi * R, 2 * math.pi * R) - math.pi * R


def weld(**keys):  # type: ignore[no-untyped-def]
    given = {
        "center": [0.3, 0.4],
        "radius": 0.05,
        "pipe_radius": R,
        "offset": 0.02,
        "arc": (-0.5 * math.pi, 1.5 * math.pi),
        "heading": "along",
        "height": 0.08,
    }
    return SaddleWeld(**{**given, **keys})


@pytest.mark.parametrize("radius", [0.03, 0.05, 0.2])
def test_offset_curve_is_where_the_widened_branch_meets_the_pipe(radius: float) -> None:
    theta = np.linspace(-4.0, 4.0, 401)
    w = weld(radius=radius, center=[0.7, 0.4])  # near the seam l = πR
    got = w.points(theta)
    expected = cylinders_meet(w.center, radius + w.offset, theta)
    assert np.allclose(wrap_l(got[:, 0] - expected[:, 0]), 0.0, atol=1e-12)
    assert np.allclose(got[:, 1], expected[:, 1], atol=1e-12)
    assert np.all(got[:, 2] == 0.08)


@pytest.mark.parametrize(
    ("heading", "turn", "arc"),
    [
        ("along", 0.0, (-0.5 * math.pi, 1.5 * math.pi)),
        ("across", 0.5 * math.pi, (-0.5 * math.pi, 1.5 * math.pi)),
        ("along", 0.0, (2.0, -4.0)),  # clockwise: along is still the direction of travel
    ],
)
def test_heading_follows_the_tangent_continuously(heading: str, turn: float, arc: tuple) -> None:
    w = weld(heading=heading, arc=arc)
    theta = np.linspace(*arc, 20001)
    lz = cylinders_meet(w.center, w.radius + w.offset, theta)
    travel = np.diff(lz, axis=0)  # finite differences of the oracle's curve
    expected = np.arctan2(travel[:, 1], travel[:, 0]) + turn
    alpha = w.points(0.5 * (theta[1:] + theta[:-1]))[:, 3]
    diff = np.mod(alpha - expected + math.pi, 2 * math.pi) - math.pi
    assert np.max(np.abs(diff)) < 1e-3
    assert np.max(np.abs(np.diff(alpha))) < 1e-3  # continuous: no jump of 2π
    turned = np.unwrap(expected)  # the oracle's tangent turns as far as the heading
    assert alpha[-1] - alpha[0] == pytest.approx(turned[-1] - turned[0], abs=1e-6)


@pytest.mark.parametrize("radius", [0.03, 0.05, 0.2])
def test_waypoints_lie_within_a_tenth_of_a_millimetre_of_the_curve(radius: float) -> None:
    w = weld(radius=radius, arc=(-1.0, 4.5))
    wp = w.waypoints()
    theta = np.linspace(-1.0, 4.5, wp.shape[0])
    assert np.allclose(wp, w.points(theta))
    dense = np.linspace(-1.0, 4.5, 200 * (wp.shape[0] - 1) + 1)
    true = w.points(dense)[:, :2]
    gap = polyline_distance(true, wp[:, :2])
    assert gap.max() <= CHORD_TOLERANCE
    assert gap.max() > 0.1 * CHORD_TOLERANCE  # not needlessly dense


def polyline_distance(points, vertices):  # type: ignore[no-untyped-def]
    """Distance of each point to the nearest segment of the polyline through ``vertices``."""
    a, b = vertices[:-1], vertices[1:]
    ab = b - a
    rel = points[:, None, :] - a[None]
    t = np.clip(np.sum(rel * ab, axis=2) / np.sum(ab * ab, axis=1), 0.0, 1.0)
    return np.min(np.linalg.norm(rel - t[..., None] * ab, axis=2), axis=1)


def test_bad_weld_parameters_are_refused() -> None:
    with pytest.raises(ParameterError, match=r"r \+ d = 0.26 m must be smaller"):
        weld(offset=0.21)
    with pytest.raises(ParameterError, match=r"needs 0 < \|θ_end − θ_start\| <= 2π"):
        weld(arc=(0.0, 7.0))
    with pytest.raises(ParameterError, match="unknown heading 'sideways'"):
        weld(heading="sideways")


TEXT = (SCENES / "saddle-weld.toml").read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            'branch = "nozzle"',
            'branch = "nozle"',
            "x.toml: motion.saddle.branch: no inlet obstacle named 'nozle' "
            "(named inlets: 'nozzle')",
        ),
        (
            'shape = "inlet"',
            'shape = "circle"',
            "x.toml: motion.saddle.branch: no inlet obstacle named 'nozzle' (named inlets: none)",
        ),
        (
            "offset = 0.02 ",
            "offset = 0.3 ",
            "x.toml: motion.saddle.offset: the scanning radius r + d = 0.33 m must be smaller than "
            "the pipe radius 0.254 m",
        ),
        (
            "arc = [-1.5708, 4.7124]",
            "arc = [1.0, 1.0]",
            "x.toml: motion.saddle.arc: needs 0 < |θ_end − θ_start| <= 2π, got [1, 1]",
        ),
        (
            "arc = [-1.5708, 4.7124]",
            "arc = [1.0]",
            "x.toml: motion.saddle.arc: expected an array of 2 numbers, got 1 values",
        ),
        (
            'heading = "along"',
            'heading = "sideways"',
            "x.toml: motion.saddle.heading: unknown heading 'sideways' (known: along, across)",
        ),
        ("h = 0.0817", "h = -0.01", "x.toml: motion.saddle.h: must be >= 0, got -0.01"),
        ("h = 0.0817", "hh = 0.0817", "x.toml: motion.saddle.hh: unknown key (did you mean 'h'?)"),
        ("speed = 0.02 ", "speed = 0.0 ", "x.toml: motion.saddle.speed: must be > 0, got 0.0"),
        (
            "\n[motion.saddle]",
            "\n[[motion.jog]]\nduration = 1.0\nvelocity = [0.0, 0.0, 0.0, 0.0]\n[motion.saddle]",
            "x.toml: motion: give exactly one of [[motion.jog]] segments, a "
            "[motion.path] or a [motion.saddle]",
        ),
    ],
)
def test_scene_errors_name_the_file_and_the_field(old: str, new: str, message: str) -> None:
    assert old in TEXT
    with pytest.raises(SceneError) as err:
        loads(TEXT.replace(old, new), "x.toml")
    assert str(err.value) == message


def test_the_branch_is_the_inlet_obstacle_and_the_path_its_offset_curve() -> None:
    sc = scene("saddle-weld")
    (nozzle,) = sc.obstacles.obstacles
    assert sc.obstacles.labels == ("nozzle",) and nozzle.kind == "inlet"
    w = sc.saddle
    assert np.array_equal(w.center, nozzle.center) and w.radius == nozzle.radius
    assert np.array_equal(sc.path.waypoints, w.waypoints())
    assert w.arc[1] - w.arc[0] == pytest.approx(2 * math.pi, abs=1e-4)  # once round
    assert (sc.path.speed, sc.path.heading_tolerance) == (0.02, 0.05)


def test_the_probe_goes_round_the_branch_on_its_offset_curve() -> None:
    sc, traj = scene("saddle-weld"), run("saddle-weld", "daqp")
    dvqp.check_run(sc, traj)  # every step verified, every limit kept, the end reached
    assert traj.success.all() and traj.limits_kept.all()
    w, tool = sc.saddle, traj.tool
    coarse = np.linspace(*w.arc, 4001)
    rel = np.column_stack([wrap_l(tool[:, 0] - w.center[0]), tool[:, 1] - w.center[1]])
    at = coarse[np.argmin(distance(rel, w, coarse), axis=1)]
    step = coarse[1] - coarse[0]  # then 2001 points of the true curve round each: 1.6 µrad
    fine = at[:, None] + np.linspace(-step, step, 2001)[None]
    near = fine[np.arange(len(tool)), np.argmin(distance(rel, w, fine), axis=1)]
    gap = np.sqrt(distance(rel, w, near[:, None])[:, 0] + (tool[:, 2] - w.height) ** 2)
    assert gap.max() < 1e-3
    heading = np.mod(tool[:, 3] - w.points(near)[:, 3] + math.pi, 2 * math.pi) - math.pi
    assert np.abs(heading).max() < sc.path.heading_tolerance
    around = np.unwrap(np.arctan2(rel[:, 1], rel[:, 0]))
    assert around[-1] - around[0] == pytest.approx(2 * math.pi, abs=0.01)  # once round
    assert np.unwrap(tool[:, 3])[-1] - tool[0, 3] == pytest.approx(2 * math.pi, abs=0.01)
    assert traj.min_clearance.min() >= 0.01 - 1e-4  # the body wound round, the margin kept


def distance(rel, w, theta):  # type: ignore[no-untyped-def]
    """Squared (l, z) distances of the points ``rel`` (relative to the branch centre, shape
    (m, 2)) to the curve at ``theta`` (shape (m, k) or (k,)), shape (m, k)."""
    theta = np.broadcast_to(theta, (rel.shape[0], np.shape(theta)[-1]))
    lz = w.points(theta.ravel())[:, :2].reshape(*theta.shape, 2) - w.center
    return np.sum((rel[:, None, :] - lz) ** 2, axis=2)
