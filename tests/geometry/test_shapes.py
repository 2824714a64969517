"""Obstacle shapes, measured by :func:`dvqp.geometry.distances` and
:func:`~dvqp.geometry.segment_distances` (the compiled kernels): signed distances of points and
segments against brute-force sampling of their outlines, normals against finite differences,
on both sides of the seam ``l = ±πR``; the circle against the paper's closed form; the
penalties; bad shapes refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from dvqp.errors import ParameterError
from dvqp.geometry import distances, segment_distances
from dvqp.geometry.proximity import measure
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon, Shape
from tests.oracles.geometry import short_way, twin, wrap


def chain_links(points: np.ndarray) -> np.ndarray:
    """The links of a chain through ``points``: i → i + 1."""
    m = points.shape[0]
    return np.stack([np.arange(m - 1), np.arange(1, m)], axis=1)


R = 0.254
PERIOD = 2.0 * math.pi * R
HALF = math.pi * R
PAD = Polygon(np.array([[0.40, 0.31], [0.46, 0.30], [0.47, 0.40], [0.41, 0.41]]))
L_SHAPE = Polygon(
    np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.03], [0.03, 0.03], [0.03, 0.1], [0.0, 0.1]])
)  # (non-convex)
SEAM = Polygon(np.array([[0.75, 0.2], [0.85, 0.2], [0.85, 0.3], [0.75, 0.3]]))  # past l = πR
INLET = Inlet(np.array([0.17, 0.25]), 0.075, R)
WIDE_INLET = Inlet(np.array([-0.3, 0.5]), 0.2, R)  # r/R = 0.79: strongly stretched in l
SEAM_INLET = Inlet(np.array([-HALF + 0.02, 0.1]), 0.075, R)  # across the seam
BAND = Band(0.46, 0.50)
CIRCLE = Circle(np.array([0.2, 0.45]), 0.06)
SEAM_CIRCLE = Circle(np.array([HALF - 0.01, -0.2]), 0.05)  # across the seam
SHAPES = [PAD, L_SHAPE, SEAM, INLET, WIDE_INLET, SEAM_INLET, BAND, CIRCLE, SEAM_CIRCLE]
IDS = [
    "pad",
    "l-shape",
    "seam-polygon",
    "inlet",
    "wide-inlet",
    "seam-inlet",
    "band",
    "circle",
    "seam-circle",
]


def point_distance(shape: Shape, lz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(d (m,), normal (m, 2))`` of m points to one shape."""
    d, n = distances([shape], np.asarray(lz, dtype=float).reshape(-1, 2), PERIOD)
    return d[0], n[0]


def segment_distance(shape: Shape, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(d (m,), t (m,), normal (m, 2))`` of m segments to one shape."""
    d, t, n = segment_distances([shape], a, b, PERIOD)
    return d[0], t[0], n[0]


def dense_outline(shape: Shape) -> tuple[np.ndarray, MplPath]:
    """The exact outline sampled every ~5 µm (unwrapped l), and a path for the inside test."""
    if isinstance(shape, Inlet):
        ring = shape.curve(200_000)
        return ring, MplPath(np.vstack([ring, ring[:1]]))
    if isinstance(shape, Circle):
        a = np.linspace(0, 2 * np.pi, 200_000, endpoint=False)
        ring = shape.center + shape.radius * np.column_stack([np.cos(a), np.sin(a)])
        return ring, MplPath(np.vstack([ring, ring[:1]]))
    v = shape.vertices  # type: ignore[attr-defined]
    along = np.linspace(0, 1, 40_000, endpoint=False)[:, None]
    ring = np.vstack([v[i] + along * (v[(i + 1) % len(v)] - v[i]) for i in range(len(v))])
    return ring, MplPath(np.vstack([v, v[:1]]))


_CACHE: dict[int, tuple[np.ndarray, MplPath]] = {}


def outline(shape: Shape) -> tuple[np.ndarray, MplPath]:
    if id(shape) not in _CACHE:
        _CACHE[id(shape)] = dense_outline(shape)
    return _CACHE[id(shape)]


def middle_l(shape: Shape) -> float:
    return 0.0 if isinstance(shape, Band) else float(outline(shape)[0][:, 0].mean())


def brute_point(shape: Shape, p: np.ndarray) -> float:
    """Signed distance of one point by brute force (l wrapped around the shape's middle)."""
    if isinstance(shape, Band):
        return max(shape.z_min - p[1], p[1] - shape.z_max)
    ring, path = outline(shape)
    ref = middle_l(shape)
    q = np.array([ref + float(wrap(p[0] - ref, PERIOD)), p[1]])
    d = float(np.sqrt(((ring - q) ** 2).sum(axis=1)).min())
    return -d if path.contains_point(q) else d


def around(shape: Shape, rng: np.random.Generator, count: int) -> np.ndarray:
    """Points near the shape, inside and out, l wrapped into [−πR, πR) as the kinematics
    give it (a shape across the seam has points on both sides of it)."""
    lo, hi = shape.z_range
    span = max(hi - lo, 0.05)
    l_mid = middle_l(shape)
    pts = np.column_stack(
        [
            l_mid + rng.uniform(-1.5 * span, 1.5 * span, count),
            rng.uniform(lo - 0.5 * span, hi + 0.5 * span, count),
        ]
    )
    pts[:, 0] = wrap(pts[:, 0], PERIOD)
    return pts


def links_around(shape: Shape, rng: np.random.Generator, count: int) -> tuple[np.ndarray, ...]:
    """Segments near the shape, at most 0.15 m long in l and z, ends wrapped."""
    a = around(shape, rng, count)
    b = a + rng.uniform(-0.15, 0.15, a.shape)
    b[:, 0] = wrap(b[:, 0], PERIOD)
    return a, b


def test_the_seam_shapes_are_sampled_on_both_sides_of_the_seam() -> None:
    for shape in (SEAM, SEAM_INLET, SEAM_CIRCLE):
        pts = around(shape, np.random.default_rng(3), 60)
        assert (pts[:, 0] > 0.9 * HALF).any() and (pts[:, 0] < -0.9 * HALF).any()


@pytest.mark.parametrize("shape", SHAPES, ids=IDS)
def test_point_distances_match_brute_force_to_a_tenth_of_a_millimetre(shape: Shape) -> None:
    pts = around(shape, np.random.default_rng(3), 60)
    d, _ = point_distance(shape, pts)
    expected = np.array([brute_point(shape, p) for p in pts])
    np.testing.assert_allclose(d, expected, atol=1e-4)
    assert (d < 0).any() and (d > 0).any()


@pytest.mark.parametrize("shape", SHAPES, ids=IDS)
def test_segment_distances_match_brute_force_and_their_closest_point(shape: Shape) -> None:
    a, b = links_around(shape, np.random.default_rng(5), 25)
    d, t, n = segment_distance(shape, a, b)
    ts = np.linspace(0, 1, 4_001)[:, None]
    ends = short_way(a, b, PERIOD)  # the link goes the short way round
    numpy_twin = twin(shape)  # 4001 samples a link, measured by the NumPy oracle
    sampled = np.array(
        [
            numpy_twin.point_distance(a[i] + ts * (ends[i] - a[i]), PERIOD)[0]
            for i in range(a.shape[0])
        ]
    )
    np.testing.assert_allclose(d, sampled.min(axis=1), atol=1e-4)
    assert (d <= sampled.min(axis=1) + 1e-12).all()  # never above a sample of the link
    at_t, n_at_t = point_distance(shape, a + t[:, None] * (ends - a))
    np.testing.assert_allclose(at_t, d, rtol=0, atol=1e-9)
    assert ((t >= 0.0) & (t <= 1.0)).all()
    plain = np.abs(n).sum(axis=1) > 0  # a link across a band's middle has no normal
    np.testing.assert_allclose(n[plain], n_at_t[plain], rtol=0, atol=1e-9)
    assert (d < 0).any() and (d > 0).any()


@pytest.mark.parametrize("shape", SHAPES, ids=IDS)
def test_the_normal_is_the_gradient_of_the_distance(shape: Shape) -> None:
    pts = around(shape, np.random.default_rng(7), 30)
    _, n = point_distance(shape, pts)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    h = 1e-7
    for axis in (0, 1):
        step = np.zeros(2)
        step[axis] = h
        fd = (point_distance(shape, pts + step)[0] - point_distance(shape, pts - step)[0]) / (2 * h)
        ok = np.abs(fd - n[:, axis]) < 1e-5
        assert ok.mean() > 0.9, (shape, axis)  # all but points on a medial axis


@pytest.mark.parametrize("shape", SHAPES, ids=IDS)
def test_segment_gradients_follow_the_envelope_theorem(shape: Shape) -> None:
    """Outside the shape: ∂d/∂a = (1 − t) n, ∂d/∂b = t n. (A segment that enters has its
    deepest point on a kink of the distance; its normal is one side's, not tested here.)"""
    a, b = links_around(shape, np.random.default_rng(11), 60)
    d, t, n = segment_distance(shape, a, b)
    out = d > 1e-4
    a, b, d, t, n = a[out], b[out], d[out], t[out], n[out]
    assert a.shape[0] >= 10
    h, good = 1e-7, 0
    for axis in (0, 1):
        step = np.zeros(2)
        step[axis] = h
        fd_a = segment_distance(shape, a + step, b)[0] - segment_distance(shape, a - step, b)[0]
        fd_b = segment_distance(shape, a, b + step)[0] - segment_distance(shape, a, b - step)[0]
        good += int(np.sum(np.abs(fd_a / (2 * h) - (1 - t) * n[:, axis]) < 1e-4))
        good += int(np.sum(np.abs(fd_b / (2 * h) - t * n[:, axis]) < 1e-4))
    assert good >= 0.95 * 4 * a.shape[0]


def test_a_segment_across_a_band_has_its_middle_depth_and_no_gradient() -> None:
    d, t, n = segment_distance(BAND, np.array([[0.1, 0.40]]), np.array([[0.3, 0.60]]))
    assert d[0] == pytest.approx(-0.02) and t[0] == pytest.approx(0.4) and not n.any()


def test_a_zero_length_link_is_its_point() -> None:
    p = np.array([[0.3, 0.42], [0.1, 0.33]])
    for shape in (CIRCLE, BAND, PAD, INLET):
        d, t, n = segment_distance(shape, p, p.copy())
        dp, np_ = point_distance(shape, p)
        np.testing.assert_allclose(d, dp, rtol=0, atol=1e-12)
        np.testing.assert_allclose(n, np_, rtol=0, atol=1e-12)
        assert np.all(np.isfinite(t)) and np.all((t >= 0) & (t <= 1))


def test_the_circle_is_the_paper_s_closed_form() -> None:
    p = np.array([[0.25, 0.40], [0.2, 0.45], [0.0, 0.0]])
    d, n = point_distance(CIRCLE, p)
    s = CIRCLE.center - p
    dist = np.linalg.norm(s, axis=1)
    np.testing.assert_allclose(d, dist - 0.06, rtol=0, atol=1e-15)
    off = [0, 2]
    np.testing.assert_allclose(n[off], -s[off] / dist[off, None], rtol=0, atol=1e-15)
    assert np.all(n[1] == 0.0)  # the centre has no normal
    near = measure([CIRCLE], p, PERIOD, chain_links(p))  # penalty ‖S − p‖² − r², ∇ −2 (S − p)
    np.testing.assert_allclose(near.point_penalty[0], dist**2 - 0.06**2, rtol=0, atol=1e-15)
    gradient = near.point_penalty_gradient[0]
    np.testing.assert_allclose(gradient[:, :2], -2 * s, rtol=0, atol=1e-15)
    assert np.all(gradient[:, 2] == 0.0)  # an unbounded circle: h does not count


@pytest.mark.parametrize("shape", SHAPES, ids=IDS)
def test_the_penalty_is_d_times_d_plus_twice_the_size_negative_exactly_inside(
    shape: Shape,
) -> None:
    chain = around(shape, np.random.default_rng(13), 40)
    near = measure([shape], chain, PERIOD, chain_links(chain))
    rho = shape.size
    for side in ("point", "link"):
        d, n = getattr(near, f"{side}_distance")[0], getattr(near, f"{side}_normal")[0]
        e, ge = getattr(near, f"{side}_penalty")[0], getattr(near, f"{side}_penalty_gradient")[0]
        n = np.concatenate([n[:, :2], np.zeros((n.shape[0], 1))], axis=1)  # a footprint: no h
        np.testing.assert_allclose(e, d * (d + 2 * rho), rtol=1e-14, atol=1e-15)
        np.testing.assert_allclose(ge, 2 * (d + rho)[:, None] * n, rtol=1e-14, atol=1e-15)
        assert ((e < 0) == (d < 0)).all()


def test_the_sizes_are_the_radius_the_half_width_and_the_circle_of_equal_area() -> None:
    assert CIRCLE.size == 0.06 and INLET.size == 0.075
    assert BAND.size == pytest.approx(0.02)
    assert L_SHAPE.size == pytest.approx(math.sqrt((0.1 * 0.03 + 0.03 * 0.07) / math.pi))


def test_a_polygon_across_the_seam_is_seen_from_both_sides() -> None:
    left_of_seam = np.array([[0.78, 0.25]])
    wrapped = np.array([[0.78 - PERIOD, 0.25]])
    assert point_distance(SEAM, left_of_seam)[0][0] < 0
    assert point_distance(SEAM, wrapped)[0][0] == pytest.approx(
        point_distance(SEAM, left_of_seam)[0][0], abs=1e-12
    )
    across = np.array([[-0.78, 0.25]])  # just past the seam, = 0.8158 unwrapped: inside
    assert point_distance(SEAM, across)[0][0] < 0


def test_a_link_across_the_seam_goes_the_short_way_round() -> None:
    a, b = np.array([[0.79, 0.25]]), np.array([[-0.79, 0.25]])  # 0.016 m apart across the seam
    d, _, _ = segment_distance(SEAM, a, b)
    assert d[0] < -0.03  # the short way lies inside the polygon, the long way would not
    d, _, _ = segment_distance(SEAM_CIRCLE, np.array([[0.7, -0.2]]), np.array([[-0.7, -0.2]]))
    assert d[0] == pytest.approx(-0.05, abs=1e-12)  # passes through the centre


def test_the_inlet_outline_is_stretched_in_l() -> None:
    half_width = float(np.ptp(WIDE_INLET.curve(4000)[:, 0])) / 2
    assert half_width == pytest.approx(R * math.asin(0.2 / R), rel=1e-6) and half_width > 0.2
    far_side = np.array([[-0.3 + math.pi * R, 0.5]])  # the branch axis, the pipe's other side
    assert point_distance(WIDE_INLET, far_side)[0][0] > 0


def test_an_empty_set_has_no_rows() -> None:
    d, n = distances([], np.zeros((3, 2)), PERIOD)
    assert d.shape == (0, 3) and n.shape == (0, 3, 2)
    d, t, n = segment_distances([], np.zeros((2, 2)), np.ones((2, 2)), PERIOD)
    assert d.shape == t.shape == (0, 2) and n.shape == (0, 2, 2)


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Polygon(np.array([[0, 0], [1, 0]])), "at least 3 vertices"),
        (lambda: Polygon(np.array([[0, 0], [1, 1], [1, 0], [0, 1]])), "edges cross"),
        (lambda: Polygon(np.array([[0, 0], [1, 1], [2, 2]])), "no area"),
        (lambda: Inlet(np.array([0.0, 0.0]), 0.3, R), "smaller than the pipe radius"),
        (lambda: Band(0.5, 0.5), "z_min < z_max"),
        (lambda: Circle(np.array([0.0, 0.0]), -1.0), "radius"),
    ],
)
def test_bad_shapes_are_refused_with_a_reason(build: object, message: str) -> None:
    with pytest.raises(ParameterError, match=message):
        build()  # type: ignore[operator]


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.2, 0.2), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2))
def test_a_segment_is_never_closer_than_its_nearest_point_says(
    la: float, za: float, lb: float, zb: float
) -> None:
    a = np.array([[0.43 + la, 0.35 + za]])
    b = np.array([[0.43 + lb, 0.35 + zb]])
    d, t, _ = segment_distance(PAD, a, b)
    ends = point_distance(PAD, np.vstack([a, b]))[0]
    assert d[0] <= ends.min() + 1e-12 and 0.0 <= t[0] <= 1.0
