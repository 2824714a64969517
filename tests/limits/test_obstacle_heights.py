"""Obstacles with a height as the dampers see them: rows of minus the gradient of the 3-D
clearance to each solid (parts over, beside and past the edge of one), and that clearance
never above the true one, which an independent sampling of the real links measures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dvqp import KinematicState, ObstacleSet, Robot
from dvqp.geometry import proximity
from dvqp.geometry.bend import PRECISION
from dvqp.limits import ObstacleDamper
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference
from tests.compiled_cases import mixed_case, paper_robot
from tests.limit_fixtures import clearance_of, configurations
from tests.oracles.resolution import frames, point_distances
from tests.safety import real_link_distances

CASE = mixed_case(paper_robot(), heights=True)


def sides(near: object, rows: list[tuple[int, int, bool]]) -> set[str]:
    """Where the given (obstacle, part, is_link) rows are: over, beside or past the edge."""
    found = set()
    for j, i, link in rows:
        n = near.real.normal[j, i] if link else near.points.normal[j, i]  # type: ignore[attr-defined]
        footprint, up = math.hypot(n[0], n[1]), n[2]
        found.add("beside" if up == 0.0 else "over" if footprint == 0.0 else "past its edge")
    return found


def test_damper_rows_are_minus_the_gradient_of_the_clearance_to_each_solid(
    robot: Robot,
) -> None:
    """Every row below the margin (a link's measured to the last PRECISION, as
    :func:`proximity` measures each) is minus the central difference of that clearance; a
    row above it (a link's may be a one-piece bound, a function of its own) is at most it."""
    margin = 0.06
    damper = ObstacleDamper(CASE.obstacles, margin=margin, influence=0.1)
    seen_obstacles, seen_sides = set(), set()
    for q in [CASE.q0, *configurations(robot, CASE.q0, 2, seed=7, spread=0.03)]:
        rows = stepping.rows(damper, robot, q)
        near = proximity(KinematicState.compute(robot, q, PIPE_RADIUS), CASE.obstacles)
        names = KinematicState.compute(robot, q, PIPE_RADIUS).part_names
        picked = []
        for row, label in zip(rows.G, rows.labels, strict=True):  # type: ignore[union-attr]
            part, name = label.split("/")
            j = CASE.obstacles.labels.index(name)
            if math.isfinite(CASE.obstacles[j].height):
                seen_obstacles.add(name)
                link = part not in names.points
                index = names.links.index(part) if link else names.points.index(part)
                picked.append((j, index, link))
            if not CASE.obstacles[j].bounded:  # walls: tests/limits/test_obstacle_damper.py
                continue
            if clearance_of(robot, q, CASE.obstacles, label) >= margin:
                continue
            fd = central_difference(
                lambda v, lab=label: clearance_of(robot, v, CASE.obstacles, lab), q, 1e-7
            )
            np.testing.assert_allclose(-row, fd, rtol=1e-6, atol=1e-7, err_msg=label)
        seen_sides |= sides(near, picked)
    assert len(seen_obstacles) >= 5
    assert seen_sides == {"over", "beside", "past its edge"}


@pytest.mark.parametrize("seed", range(4))
def test_the_clearance_to_a_solid_is_never_above_the_sampled_true_one(
    robot: Robot, seed: int
) -> None:
    """Points exactly; links' real (bent) images, sampled in 3-D and each sample mapped to the
    developed view: dvqp's clearance is at most the sampled one, and the closest part's within
    PRECISION of it."""
    period = 2.0 * math.pi * PIPE_RADIUS
    obstacles = ObstacleSet(list(CASE.obstacles))
    for q in configurations(robot, CASE.q0, 3, seed=seed, spread=0.06):
        near = proximity(KinematicState.compute(robot, q, PIPE_RADIUS), obstacles)
        f = frames(robot, q, PIPE_RADIUS)
        points = point_distances(obstacles, f.guarded[:, :3], period)
        np.testing.assert_allclose(near.point_clearance, points, rtol=0, atol=1e-7)
        sampled = real_link_distances(obstacles, f, PIPE_RADIUS)
        assert (near.link_clearance <= sampled + 1e-9).all()
        true = min(points.min(), sampled.min())
        assert true - PRECISION - 1e-7 <= near.min_clearance() <= true + 1e-9


def test_an_unbounded_obstacle_is_measured_as_its_footprint(robot: Robot) -> None:
    """Without heights, the same shapes give the footprints' clearances, whatever the parts'
    heights."""
    flat = mixed_case(paper_robot())
    near = proximity(KinematicState.compute(robot, flat.q0, PIPE_RADIUS), flat.obstacles)
    f = frames(robot, flat.q0, PIPE_RADIUS)
    period = 2.0 * math.pi * PIPE_RADIUS
    np.testing.assert_allclose(
        near.point_clearance, point_distances(flat.obstacles, f.guarded[:, :2], period), atol=1e-7
    )
    assert (near.points.normal[..., 2] == 0.0).all()
