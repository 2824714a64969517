"""The shapes' compiled proximity kernels against the reference :func:`proximity`: every
class, in scenes and in interleaved sets, with points inside and across the seam."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from dvqp import ObstacleSet
from dvqp.compiled import ProximityBuffers, StepPlan
from dvqp.geometry.proximity import Proximity, proximity
from dvqp.geometry.shapes import Band, Circle, Shape
from tests.compiled_cases import (
    BUNDLED_WITH_OBSTACLES,
    Case,
    Dot,
    mixed_case,
    paper_robot,
    run,
    scene_case,
    spoil,
)

FIELDS = ("distance", "normal", "penalty", "penalty_gradient")


def assert_matches(buffers: ProximityBuffers, reference: Proximity) -> None:
    """Every buffer equals the reference to 1e-12 (absolute)."""
    for side in ("point", "link"):
        found = getattr(reference, f"{side}s")
        for name in FIELDS:
            got, want = getattr(buffers, f"{side}_{name}"), getattr(found, name)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12, err_msg=f"{side} {name}")
    np.testing.assert_allclose(buffers.link_t, reference.links.t, rtol=0, atol=1e-12)


def compare(case: Case, count: int, spread: float) -> list[Proximity]:
    """Kernels and reference at ``count`` configurations, on one plan; the references."""
    robot_state = case.state(case.q0)
    plan = StepPlan(robot_state.n, robot_state.k, case.radius)
    buffers = plan.proximity(case.obstacles)
    assert buffers is not None
    references = []
    for q in case.configurations(count, spread):
        state = case.state(q)
        plan.state.load(state)
        spoil(*(getattr(buffers, f) for f in buffers.__dataclass_fields__))
        run(plan, plan.geometry)
        reference = proximity(state, case.obstacles)
        assert_matches(buffers, reference)
        references.append(reference)
    return references


@pytest.mark.parametrize("name", BUNDLED_WITH_OBSTACLES)
def test_compiled_proximity_equals_the_reference_in_bundled_scenes(name: str) -> None:
    compare(scene_case(name), count=30, spread=0.3)


@pytest.mark.parametrize("seam", [False, True], ids=["inside", "across-seam"])
def test_compiled_proximity_equals_the_reference_with_parts_inside_interleaved_shapes(
    seam: bool,
) -> None:
    case = mixed_case(paper_robot(), seam)
    references = compare(case, count=40, spread=0.1)
    points_inside = sum((r.points.penalty < 0).sum(axis=1) for r in references)
    links_inside = sum((r.links.distance < 0).sum(axis=1) for r in references)
    # every shape but the far circle has a link inside it, and all but two a point
    assert (links_inside > 0).sum() == len(case.obstacles) - 1
    assert (points_inside > 0).sum() == len(case.obstacles) - 2


def test_the_seam_case_has_a_point_on_either_side_of_the_seam() -> None:
    case = mixed_case(paper_robot(), seam=True)
    l4 = np.array([case.state(q).guarded[3, 0] for q in case.configurations(40, 0.1)])
    half = np.pi * case.radius
    assert (l4 > 0.9 * half).any() and (l4 < -0.9 * half).any()


def test_rows_follow_the_order_of_the_set_not_the_grouping_by_class() -> None:
    robot = paper_robot()
    case = mixed_case(robot)
    state = case.state(case.q0)
    lz = state.guarded[:, :2]
    shapes: Sequence[Shape] = [
        Circle(lz[1] + [0.01, 0.0], 0.05),
        Band(lz[2, 1] - 0.01, lz[2, 1] + 0.03),
        Circle(lz[4] + [0.0, 0.02], 0.03),
    ]
    obstacles = ObstacleSet(shapes)
    plan = StepPlan(state.n, state.k, case.radius)
    buffers = plan.proximity(obstacles)
    assert buffers is not None and len(plan.geometry) == 2  # one kernel per class
    plan.state.load(state)
    run(plan, plan.geometry)
    for row, shape in enumerate(shapes):
        d, n = shape.point_distance(lz, 2 * np.pi * case.radius)
        np.testing.assert_allclose(buffers.point_distance[row], d, rtol=0, atol=1e-12)
        np.testing.assert_allclose(buffers.point_normal[row], n, rtol=0, atol=1e-12)
    assert_matches(buffers, proximity(state, obstacles))


def test_an_empty_set_has_empty_buffers_and_no_geometry_kernel() -> None:
    plan = StepPlan(13, 5, 0.254)
    buffers = plan.proximity(ObstacleSet())
    assert buffers is not None and plan.geometry == []
    assert buffers.point_distance.shape == (0, 6) and buffers.link_t.shape == (0, 5)


def test_a_shape_class_without_kernel_makes_the_set_uncompiled() -> None:
    plan = StepPlan(13, 5, 0.254)
    obstacles = ObstacleSet([Circle([0.1, 0.2], 0.05), Dot([0.3, 0.3], 0.05)])
    assert plan.proximity(obstacles) is None


def test_the_buffers_are_shared_and_their_kernels_added_once_per_set() -> None:
    plan = StepPlan(13, 5, 0.254)
    obstacles = mixed_case(paper_robot()).obstacles
    first = plan.proximity(obstacles)
    count = len(plan.geometry)
    assert plan.proximity(obstacles) is first and len(plan.geometry) == count == 4
