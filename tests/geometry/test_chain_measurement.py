"""The compiled measurement of a whole guarded chain (:func:`dvqp.geometry.proximity`, i.e.
``measure_chain``) against independent NumPy distances (shapes of one's own with the same
geometry), against per-point and per-link calls, and in the order of the set: every class, in
the bundled scenes and in interleaved sets with points inside and across the seam."""

from __future__ import annotations

import math

import numpy as np
import pytest

from dvqp import KinematicState, ObstacleSet
from dvqp.geometry import distances, min_clearance, proximity, segment_distances
from dvqp.geometry.proximity import Proximity
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon
from tests.compiled_cases import (
    BUNDLED_WITH_OBSTACLES,
    Case,
    Dot,
    mixed_case,
    paper_robot,
    scene_case,
)
from tests.oracles.geometry import (
    UserCircle,
    inlet_nearest_normals,
    polygon_points,
    short_way,
    twin,
)
from tests.oracles.limits import guarded_links, link_name, point_name

FIELDS = ("distance", "normal", "penalty", "penalty_gradient", "t")


def states(case: Case, count: int, spread: float) -> list[KinematicState]:
    return [case.state(q) for q in case.configurations(count, spread)]


def links_of(state: KinematicState) -> tuple[np.ndarray, np.ndarray]:
    """``[l, z]`` of the starts and ends of the guarded links (the oracle's list)."""
    ends = guarded_links(state.k, state.rail)
    lz = state.guarded[:, :2]
    return lz[ends[:, 0]], lz[ends[:, 1]]


def assert_rows_equal(got: Proximity, want: Proximity, rows: list[int], atol: float) -> None:
    """Rows ``rows`` (obstacles) of two proximities agree, every field of points and links."""
    for side in ("points", "links"):
        for name in FIELDS:
            a, b = getattr(getattr(got, side), name)[rows], getattr(getattr(want, side), name)[rows]
            np.testing.assert_allclose(a, b, rtol=0, atol=atol, err_msg=f"{side} {name}")


def assert_matches_the_oracle(state: KinematicState, obstacles: ObstacleSet) -> Proximity:
    """dvqp's compiled rows equal those of the NumPy twins (measured through the same
    ``proximity``, as shapes of one's own): exactly for points, circles and bands; for a
    polygon's links, the outside ones exactly, the entering ones' depth to 1e-9 with their
    ``t`` and normal those of a point at that depth; an inlet's (a search on its curve in the
    oracle) to 1e-9 m, the normals to 1e-6."""
    mine = proximity(state, obstacles)
    numpy = proximity(state, [twin(s) for s in obstacles])
    exact = [j for j, s in enumerate(obstacles) if isinstance(s, Circle | Band)]
    assert_rows_equal(mine, numpy, exact, 1e-12)
    inlets = np.array([isinstance(s, Inlet) for s in obstacles])
    for name in ("distance", "normal", "penalty", "penalty_gradient"):
        a, b = getattr(mine.points, name), getattr(numpy.points, name)
        np.testing.assert_allclose(
            a[~inlets], b[~inlets], rtol=0, atol=1e-12, err_msg=f"points {name}"
        )
        tol = 1e-6 if "normal" in name or "gradient" in name else 1e-9
        np.testing.assert_allclose(a[inlets], b[inlets], rtol=0, atol=tol, err_msg=name)
    period = 2 * math.pi * state.radius
    for j, shape in enumerate(obstacles):
        if not isinstance(shape, Polygon | Inlet):
            continue
        d, t, n = mine.links.distance[j], mine.links.t[j], mine.links.normal[j]
        assert not n[:, 2].any()  # an unbounded obstacle's normals lie in the (l, z) plane
        n = n[:, :2]
        starts, stops = links_of(state)
        ends = short_way(starts, stops, period)
        if isinstance(shape, Inlet):
            np.testing.assert_allclose(d, numpy.links.distance[j], rtol=0, atol=1e-9)
            at = starts + t[:, None] * (ends - starts)
            at_t, _ = twin(shape).point_distance(at, period)
            np.testing.assert_allclose(at_t, d, rtol=0, atol=1e-9)
            for p, normal in zip(at, n, strict=True):  # on the medial axis, either side's
                normals = inlet_nearest_normals(
                    shape.center, shape.radius, shape.pipe_radius, p, period
                )
                assert any(np.abs(normal - m).max() < 1e-6 for m in normals), (normal, normals)
            continue
        out = numpy.links.distance[j] > 1e-9
        for name in ("distance", "t", "normal"):
            a, b = getattr(mine.links, name)[j][out], getattr(numpy.links, name)[j][out]
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12, err_msg=f"link {name} {j}")
        np.testing.assert_allclose(d, numpy.links.distance[j], rtol=0, atol=1e-9)
        at_t, n_at_t = polygon_points(shape.vertices, starts + t[:, None] * (ends - starts), period)
        np.testing.assert_allclose(at_t, d, rtol=0, atol=1e-12)
        np.testing.assert_allclose(n_at_t, n, rtol=0, atol=1e-9)
    return mine


@pytest.mark.parametrize("name", BUNDLED_WITH_OBSTACLES)
def test_the_chain_measurement_equals_the_numpy_oracle_in_bundled_scenes(name: str) -> None:
    case = scene_case(name)
    for state in states(case, 30, 0.3):
        assert_matches_the_oracle(state, case.obstacles)


@pytest.mark.parametrize("seam", [False, True], ids=["inside", "across-seam"])
def test_the_chain_measurement_equals_the_numpy_oracle_with_parts_inside_interleaved_shapes(
    seam: bool,
) -> None:
    case = mixed_case(paper_robot(), seam)
    found = [assert_matches_the_oracle(s, case.obstacles) for s in states(case, 16, 0.1)]
    points_inside = sum((r.points.penalty < 0).sum(axis=1) for r in found)
    links_inside = sum((r.links.distance < 0).sum(axis=1) for r in found)
    # every shape but the far circle has a link inside it, and all but two a point
    assert (links_inside > 0).sum() == len(case.obstacles) - 1
    assert (points_inside > 0).sum() == len(case.obstacles) - 2


def test_the_seam_case_has_a_point_on_either_side_of_the_seam() -> None:
    case = mixed_case(paper_robot(), seam=True)
    l4 = np.array([s.guarded[3, 0] for s in states(case, 40, 0.1)])
    half = np.pi * case.radius
    assert (l4 > 0.9 * half).any() and (l4 < -0.9 * half).any()


@pytest.mark.parametrize("name", [*BUNDLED_WITH_OBSTACLES, "mixed", "mixed-seam"])
def test_the_chain_measurement_equals_per_point_and_per_link_calls(name: str) -> None:
    """Point i of the chain is guarded point i, link i joins the oracle's pair of points (the
    body links, the probe holder, the carriage link), the penalty rows follow each shape's
    size."""
    case = mixed_case(paper_robot(), name == "mixed-seam") if "mixed" in name else scene_case(name)
    period = 2 * math.pi * case.radius
    rho = np.array([s.size for s in case.obstacles])[:, None]
    for state in states(case, 3, 0.1):
        chain = proximity(state, case.obstacles)
        lzh = state.guarded
        for i in range(lzh.shape[0]):
            d, n = distances(case.obstacles, lzh[i : i + 1], period)
            np.testing.assert_array_equal(chain.points.distance[:, i : i + 1], d)
            np.testing.assert_array_equal(chain.points.normal[:, i : i + 1], n)
        starts, stops = links_of(state)
        for i in range(starts.shape[0]):
            d, t, n = segment_distances(case.obstacles, starts[i : i + 1], stops[i : i + 1], period)
            np.testing.assert_array_equal(chain.links.distance[:, i : i + 1], d)
            np.testing.assert_array_equal(chain.links.t[:, i : i + 1], t)
            np.testing.assert_array_equal(chain.links.normal[:, i : i + 1, :2], n)
        assert not chain.points.t.any()
        for part in (chain.points, chain.links):
            d = part.distance
            np.testing.assert_allclose(part.penalty, d * (d + 2 * rho), rtol=1e-14, atol=1e-16)
            gradient = 2 * (d + rho)[..., None] * part.normal
            np.testing.assert_allclose(part.penalty_gradient, gradient, rtol=1e-14, atol=1e-16)


def test_rows_follow_the_order_of_the_set_not_the_grouping_by_class() -> None:
    case = mixed_case(paper_robot())
    state = case.state(case.q0)
    period = 2 * np.pi * case.radius
    chain = proximity(state, case.obstacles)
    assert len({type(s) for s in case.obstacles}) == 4
    for row, shape in enumerate(case.obstacles):
        d, n = distances([shape], state.guarded, period)
        np.testing.assert_array_equal(chain.points.distance[row], d[0])
        np.testing.assert_array_equal(chain.points.normal[row], n[0])
        d, t, n = segment_distances([shape], *links_of(state), period)
        np.testing.assert_array_equal(chain.links.distance[row], d[0])
        np.testing.assert_array_equal(chain.links.t[row], t[0])
        np.testing.assert_array_equal(chain.links.normal[row, :, :2], n[0])


def test_shapes_of_one_s_own_among_dvqp_s_give_the_rows_of_the_same_geometry() -> None:
    """A set interleaving dvqp's shapes with shapes of one's own (a :class:`Shape` subclass,
    and :class:`Dot`, a subclass of dvqp's :class:`Circle`): each of one's own is measured by
    its NumPy methods into its own rows, equal to those of dvqp's twin."""
    case = mixed_case(paper_robot(), seam=True)
    circle = next(s for s in case.obstacles if type(s) is Circle)
    band = next(s for s in case.obstacles if type(s) is Band)
    polygon = next(s for s in case.obstacles if type(s) is Polygon)
    dot = Dot(circle.center, circle.radius, circle.weight)
    shapes = [circle, twin(band), polygon, band, dot, twin(polygon), twin(circle)]
    assert isinstance(shapes[-1], UserCircle)
    Dot.calls.clear()
    for state in states(case, 10, 0.1):
        near = proximity(state, ObstacleSet(shapes))
        for mine, own in ((0, 4), (0, 6), (3, 1), (2, 5)):
            for side in ("points", "links"):
                for name in FIELDS:
                    if own == 5 and side == "links":  # the deepest point of a link, searched
                        continue
                    got = getattr(getattr(near, side), name)
                    np.testing.assert_allclose(
                        got[own], got[mine], rtol=0, atol=1e-12, err_msg=f"{side} {name} {own}"
                    )
        np.testing.assert_allclose(near.links.distance[5], near.links.distance[2], atol=1e-9)
    assert Dot.calls.count("point_distance") == Dot.calls.count("segment_distance") == 10


def test_an_empty_set_has_empty_rows_and_no_clearance_limit(state0: KinematicState) -> None:
    near = proximity(state0, ObstacleSet())
    assert near.points.distance.shape == (0, 7) and near.links.t.shape == (0, 6)
    assert near.points.normal.shape == (0, 7, 3) and near.links.penalty_gradient.shape == (0, 6, 3)
    assert near.min_clearance() == math.inf and near.probe_clearance() == math.inf
    assert min_clearance(state0, ObstacleSet()) == math.inf
    with pytest.raises(ValueError):
        near.closest()


def test_the_clearances_name_the_closest_part_and_obstacle() -> None:
    case = mixed_case(paper_robot())
    for state in states(case, 10, 0.1):
        near = proximity(state, case.obstacles)
        points, links = near.point_clearance, near.link_clearance
        smallest = min(points.min(), links.min())
        assert near.min_clearance() == smallest == min_clearance(state, case.obstacles)
        assert near.probe_clearance() == min(points[:, 5].min(), links[:, 4].min())
        value, part, j = near.closest()
        assert value == smallest
        if links.min() < points.min():
            i = int(np.argmin(links[j]))
            assert links[j, i] == value and part == link_name(i, 5)
        else:
            i = int(np.argmin(points[j]))
            assert points[j, i] == value and part == point_name(i, 5)
