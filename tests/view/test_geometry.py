"""The 3-D geometry of the view and the still, against independent facts: the pipe's surface at
radius R, the DV map's inverse, an inlet's tube normal to the pipe and meeting it on the
inlet's outline, a band's ring, a pad's raised patch covering the pad, the arm's chain equal
to Pinocchio's frames, and the links at their margin where the run recorded its clearance
there."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from dvqp.geometry import distances
from dvqp.geometry.shapes import Band, Inlet, Polygon
from dvqp.kinematics.state import KinematicState
from dvqp.view import meshes, scene3d
from tests import runs

R = 0.254


def dv_of(points: np.ndarray) -> np.ndarray:
    """[l, z, h] of 3-D points (theory §2), independent of the module under test."""
    return np.column_stack(
        [
            R * np.arctan2(points[:, 1], points[:, 0]),
            points[:, 2],
            np.hypot(points[:, 0], points[:, 1]) - R,
        ]
    )


def test_every_pipe_vertex_lies_on_the_pipe_surface() -> None:
    mesh = meshes.pipe_mesh(R, -0.1, 0.6, (0, 0, 0))
    assert np.allclose(np.hypot(mesh.vertices[:, 0], mesh.vertices[:, 1]), R, atol=1e-14)
    assert mesh.vertices[:, 2].min() == -0.1 and mesh.vertices[:, 2].max() == 0.6
    assert np.diff(np.unique(mesh.vertices[:, 2])).max() <= meshes.ROW + 1e-12
    assert mesh.faces.min() == 0 and mesh.faces.max() == len(mesh.vertices) - 1


def test_surface_points_invert_the_compiled_developed_view_map() -> None:
    scene = runs.scene("paper-two-inlets")
    rng = np.random.default_rng(3)
    for q in scene.q0 + rng.normal(0.0, 0.2, (5, scene.robot.n)):
        state = KinematicState.compute(scene.robot, q, R)
        g = np.asarray(state.guarded)
        back = meshes.surface_points(g[:, 0], g[:, 1], g[:, 2], R)
        assert np.allclose(back, state.origins, atol=1e-12)


def test_an_inlet_is_a_tube_normal_to_the_pipe_meeting_it_on_its_outline() -> None:
    center, r = np.array([0.33, 0.22]), 0.06
    mesh = scene3d.obstacle_mesh("inlet", Inlet(center, r, R), R)
    # the surface normal at the centre, by finite differences of the map (l, z) -> 3-D
    eps = 1e-6
    base = meshes.surface_points(*center, 0.0, R)
    dl = (meshes.surface_points(center[0] + eps, center[1], 0.0, R) - base) / eps
    dz = (meshes.surface_points(center[0], center[1] + eps, 0.0, R) - base) / eps
    normal = np.cross(dl, dz) / np.linalg.norm(np.cross(dl, dz))
    offset = mesh.vertices - base
    from_axis = offset - np.outer(offset @ normal, normal)
    assert np.allclose(np.linalg.norm(from_axis, axis=1), r, atol=1e-12)
    rim = mesh.vertices[: meshes.TUBE_ROUND]  # the first row: where the tube meets the pipe
    l, z, h = dv_of(rim).T
    assert np.allclose(h, 0.0, atol=1e-12)
    assert np.allclose((R * np.sin((l - center[0]) / R)) ** 2 + (z - center[1]) ** 2, r * r)
    d, _ = distances([Inlet(center, r, R)], np.column_stack([l, z]), 2 * math.pi * R)
    assert np.abs(d).max() < 1e-9
    assert (offset @ normal).max() == pytest.approx(scene3d.TUBE_LENGTH)  # drawn this far out


def test_a_band_is_a_ring_round_the_pipe() -> None:
    mesh = scene3d.obstacle_mesh("band", Band(0.46, 0.50), R)
    l, z, h = dv_of(mesh.vertices).T
    assert set(np.round(z, 12)) == {0.46, 0.50}
    assert np.all(np.isclose(h, 0.0, atol=1e-12) | np.isclose(h, scene3d.RING_HEIGHT, atol=1e-12))
    assert np.ptp(l) > 2 * math.pi * R * 0.95  # all the way round


def test_a_pad_is_its_outline_raised_with_a_top_covering_it() -> None:
    corners = np.array(
        [[0.0, 0.0], [0.12, 0.0], [0.12, 0.05], [0.04, 0.05], [0.04, 0.15], [0.0, 0.15]]
    )  # an L: not convex
    pad = Polygon(corners)
    mesh = scene3d.obstacle_mesh("pad", pad, R)
    lz_h = dv_of(mesh.vertices)
    n = len(corners)
    assert np.allclose(lz_h[:n, :2], corners) and np.allclose(lz_h[:n, 2], 0.0, atol=1e-12)
    top = np.unique(mesh.faces[2 * n :])  # after the wall's 2n triangles
    assert np.allclose(lz_h[top, 2], scene3d.PATCH_HEIGHT, atol=1e-12)
    tri = lz_h[mesh.faces[2 * n :], :2]
    cross = (tri[:, 1, 0] - tri[:, 0, 0]) * (tri[:, 2, 1] - tri[:, 0, 1]) - (
        tri[:, 1, 1] - tri[:, 0, 1]
    ) * (tri[:, 2, 0] - tri[:, 0, 0])
    assert np.sum(np.abs(cross)) / 2 == pytest.approx(0.12 * 0.05 + 0.04 * 0.10, rel=1e-9)
    d, _ = distances([pad], tri.mean(axis=1), 2 * math.pi * R)
    assert d.max() < 0.0  # every top triangle inside the pad
    edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2)
    assert edges.max() <= meshes.ROW + 1e-12  # close to the curved surface


@pytest.mark.parametrize("seed", range(5))
def test_triangulation_of_a_simple_polygon_either_way_round(seed: int) -> None:
    rng = np.random.default_rng(seed)
    angle = np.sort(rng.uniform(0, 2 * np.pi, 14))
    poly = rng.uniform(0.3, 1.0, 14)[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    area = 0.5 * abs(
        np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
    )
    for p in (poly, poly[::-1]):
        t = meshes.triangulate(p)
        assert t.shape == (12, 3)
        a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
        cross = (b - a)[:, 0] * (c - a)[:, 1] - (b - a)[:, 1] * (c - a)[:, 0]
        assert np.all(cross > 0) and np.sum(cross) / 2 == pytest.approx(area, rel=1e-12)


def test_the_arm_chain_is_the_robots_frames_and_marks_the_links_at_their_margin() -> None:
    scene, traj = runs.scene("paper-two-inlets"), runs.run("paper-two-inlets", "pinv")
    view = scene3d.scene_3d(scene, traj.q, traj.t, "pinv")
    model = scene.robot.model
    data = model.createData()
    names = ["rail", "point1", "point2", "point3", "point4", "point5", "tool"]
    for n in (0, len(traj.t) // 2, len(traj.t) - 1):
        pin.framesForwardKinematics(model, data, traj.q[n])
        frames = [data.oMf[model.getFrameId(name)].translation for name in names]
        assert np.allclose(view.chain[n], frames, atol=1e-12)
    assert np.allclose(view.lines[-1].points, view.chain[:, -1])  # the probe's path
    # the run recorded its smallest clearance of any part (links include their ends)
    near = traj.min_clearance <= view.margin + scene3d.MARGIN_SLACK
    assert near.sum() > 50 and (~near).sum() > 50  # the baseline goes into the margin
    assert np.array_equal(view.at_margin.any(axis=1), near)
    # each link on its own: its real 3-D segment sampled densely, measured to the circles
    along = np.linspace(0.0, 1.0, 2001)[:, None]
    checked = 0
    for n in range(0, len(traj.t), 10):
        for i in range(view.chain.shape[1] - 1):
            a, b = view.chain[n, i], view.chain[n, i + 1]
            lz = dv_of(a + along * (b - a))[:, :2]
            clearance = min(
                np.min(
                    np.hypot(
                        (lz[:, 0] - c.center[0] + math.pi * R) % (2 * math.pi * R) - math.pi * R,
                        lz[:, 1] - c.center[1],
                    )
                    - c.radius
                )
                for c in scene.obstacles
            )
            if abs(clearance - view.margin - scene3d.MARGIN_SLACK) > 1e-4:  # not on the edge
                assert view.at_margin[n, i] == (clearance <= view.margin + scene3d.MARGIN_SLACK)
                checked += view.at_margin[n, i]
    assert checked > 20
