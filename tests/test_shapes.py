"""Obstacle shapes: signed distances of points and segments against brute-force sampling of
their outlines, gradients against finite differences, the circle against its closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from dvqp.errors import ParameterError
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon, Shape

R = 0.254
PERIOD = 2.0 * math.pi * R
PAD = Polygon(np.array([[0.40, 0.31], [0.46, 0.30], [0.47, 0.40], [0.41, 0.41]]))
L_SHAPE = Polygon(
    np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.03], [0.03, 0.03], [0.03, 0.1], [0.0, 0.1]])
)  # fmt: skip  (non-convex)
SEAM = Polygon(np.array([[0.75, 0.2], [0.85, 0.2], [0.85, 0.3], [0.75, 0.3]]))  # past l = πR
INLET = Inlet(np.array([0.17, 0.25]), 0.075, R)
WIDE_INLET = Inlet(np.array([-0.3, 0.5]), 0.2, R)  # r/R = 0.79: strongly stretched in l
BAND = Band(0.46, 0.50)
CIRCLE = Circle(np.array([0.2, 0.45]), 0.06)
SHAPES = [PAD, L_SHAPE, SEAM, INLET, WIDE_INLET, BAND, CIRCLE]


def dense_outline(shape: Shape) -> tuple[np.ndarray, MplPath | None]:
    """The outline sampled every ~5 µm, and a path for the inside test (None for a band)."""
    if isinstance(shape, Inlet):
        ring = shape.curve(200_000)
        return ring, MplPath(np.vstack([ring, ring[:1]]))
    if isinstance(shape, Circle):
        a = np.linspace(0, 2 * np.pi, 200_000, endpoint=False)
        ring = shape.center + shape.radius * np.column_stack([np.cos(a), np.sin(a)])
        return ring, MplPath(np.vstack([ring, ring[:1]]))
    v = shape.vertices  # type: ignore[attr-defined]
    along = np.linspace(0, 1, 40_000, endpoint=False)[:, None]
    edges = [v[i] + along * (v[(i + 1) % len(v)] - v[i]) for i in range(len(v))]
    ring = np.vstack(edges)
    return ring, MplPath(np.vstack([v, v[:1]]))


def brute_point(shape: Shape, p: np.ndarray) -> float:
    """Signed distance of one point by brute force (l wrapped around the shape)."""
    if isinstance(shape, Band):
        return max(shape.z_min - p[1], p[1] - shape.z_max)
    ring, path = dense_outline_cached(shape)
    ref = float(ring[:, 0].mean())
    q = np.array([ref + ((p[0] - ref + PERIOD / 2) % PERIOD - PERIOD / 2), p[1]])
    d = float(np.sqrt(((ring - q) ** 2).sum(axis=1)).min())
    return -d if path is not None and path.contains_point(q) else d


_CACHE: dict[int, tuple[np.ndarray, MplPath | None]] = {}


def dense_outline_cached(shape: Shape) -> tuple[np.ndarray, MplPath | None]:
    if id(shape) not in _CACHE:
        _CACHE[id(shape)] = dense_outline(shape)
    return _CACHE[id(shape)]


def around(shape: Shape, rng: np.random.Generator, count: int) -> np.ndarray:
    """Points near the shape, inside and out."""
    lo, hi = shape.z_range
    if isinstance(shape, Band):
        l_mid = 0.0
    else:
        ring = dense_outline_cached(shape)[0]
        l_mid = float(ring[:, 0].mean())
    span = max(hi - lo, 0.05)
    return np.column_stack([
        l_mid + rng.uniform(-1.5 * span, 1.5 * span, count),
        rng.uniform(lo - 0.5 * span, hi + 0.5 * span, count),
    ])  # fmt: skip


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_point_distances_match_brute_force_to_a_tenth_of_a_millimetre(shape: Shape) -> None:
    pts = around(shape, np.random.default_rng(3), 60)
    d, _ = shape.point_distance(pts, PERIOD)
    expected = np.array([brute_point(shape, p) for p in pts])
    np.testing.assert_allclose(d, expected, atol=1e-4)
    assert (d < 0).any() and (d > 0).any()


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_segment_distances_match_brute_force_and_their_closest_point(shape: Shape) -> None:
    rng = np.random.default_rng(5)
    a = around(shape, rng, 25)
    b = a + rng.uniform(-0.15, 0.15, a.shape)  # links are at most 0.15 m long
    d, t, _ = shape.segment_distance(a, b, PERIOD)
    for i in range(a.shape[0]):
        ts = np.linspace(0, 1, 4_001)
        samples = a[i] + ts[:, None] * (b[i] - a[i])
        brute = min(shape.point_distance(samples, PERIOD)[0])
        assert d[i] == pytest.approx(brute, abs=1e-4), i
        at_t = shape.point_distance((a[i] + t[i] * (b[i] - a[i]))[None], PERIOD)[0][0]
        assert at_t == pytest.approx(d[i], abs=1e-9)


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_the_normal_is_the_gradient_of_the_distance(shape: Shape) -> None:
    pts = around(shape, np.random.default_rng(7), 30)
    _, n = shape.point_distance(pts, PERIOD)
    h = 1e-7
    for axis in (0, 1):
        step = np.zeros(2)
        step[axis] = h
        fd = (
            shape.point_distance(pts + step, PERIOD)[0]
            - shape.point_distance(pts - step, PERIOD)[0]
        ) / (2 * h)
        ok = np.abs(fd - n[:, axis]) < 1e-5
        assert ok.mean() > 0.9, (shape.kind, axis)  # all but points on a medial axis


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.kind)
def test_segment_gradients_follow_the_envelope_theorem(shape: Shape) -> None:
    """Outside the shape: ∂d/∂a = (1 − t) n, ∂d/∂b = t n. (A segment that enters has its
    deepest point on a kink of the distance; its normal is one side's, not tested here.)"""
    rng = np.random.default_rng(11)
    a = around(shape, rng, 60)
    b = a + rng.uniform(-0.15, 0.15, a.shape)
    d, t, n = shape.segment_distance(a, b, PERIOD)
    a, b, d, t, n = a[d > 1e-4], b[d > 1e-4], d[d > 1e-4], t[d > 1e-4], n[d > 1e-4]
    assert a.shape[0] >= 10
    h, good = 1e-7, 0
    for axis in (0, 1):
        step = np.zeros(2)
        step[axis] = h
        fd_a = (
            shape.segment_distance(a + step, b, PERIOD)[0]
            - shape.segment_distance(a - step, b, PERIOD)[0]
        ) / (2 * h)
        fd_b = (
            shape.segment_distance(a, b + step, PERIOD)[0]
            - shape.segment_distance(a, b - step, PERIOD)[0]
        ) / (2 * h)
        good += int(np.sum(np.abs(fd_a - (1 - t) * n[:, axis]) < 1e-4))
        good += int(np.sum(np.abs(fd_b - t * n[:, axis]) < 1e-4))
    assert good >= 0.95 * 4 * a.shape[0]


def test_a_segment_across_a_band_has_its_middle_depth_and_no_gradient() -> None:
    d, t, n = BAND.segment_distance(np.array([[0.1, 0.40]]), np.array([[0.3, 0.60]]), PERIOD)
    assert d[0] == pytest.approx(-0.02) and t[0] == pytest.approx(0.4) and not n.any()


def test_the_circle_is_the_paper_s_closed_form() -> None:
    p = np.array([[0.25, 0.40], [0.2, 0.45], [0.0, 0.0]])
    d, n = CIRCLE.point_distance(p, PERIOD)
    s = CIRCLE.center - p
    dist = np.linalg.norm(s, axis=1)
    np.testing.assert_allclose(d, dist - 0.06)
    assert np.all(n[1] == 0.0)  # the centre has no normal
    batch = Circle.batch_points([CIRCLE], p, PERIOD)
    np.testing.assert_allclose(batch.penalty[0], dist**2 - 0.06**2)
    np.testing.assert_allclose(batch.penalty_gradient[0], -2 * s)


def test_a_polygon_across_the_seam_is_seen_from_both_sides() -> None:
    left_of_seam = np.array([[0.78, 0.25]])
    wrapped = np.array([[0.78 - PERIOD, 0.25]])
    assert SEAM.point_distance(left_of_seam, PERIOD)[0][0] < 0
    assert SEAM.point_distance(wrapped, PERIOD)[0][0] == pytest.approx(
        SEAM.point_distance(left_of_seam, PERIOD)[0][0], abs=1e-12
    )
    across = np.array([[-0.78, 0.25]])  # just past the seam, = 0.8158 unwrapped: inside
    assert SEAM.point_distance(across, PERIOD)[0][0] < 0


def test_the_inlet_outline_is_stretched_in_l() -> None:
    half_width = float(np.ptp(WIDE_INLET.curve(4000)[:, 0])) / 2
    assert half_width == pytest.approx(R * math.asin(0.2 / R), rel=1e-6) and half_width > 0.2
    far_side = np.array([[-0.3 + math.pi * R, 0.5]])  # the branch axis, the pipe's other side
    assert WIDE_INLET.point_distance(far_side, PERIOD)[0][0] > 0


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
    d, t, _ = PAD.segment_distance(a, b, PERIOD)
    ends = PAD.point_distance(np.vstack([a, b]), PERIOD)[0]
    assert d[0] <= ends.min() + 1e-12 and 0.0 <= t[0] <= 1.0
