"""The signed distance to an obstacle with a height (its footprint extruded up to it): the
law case by case, its slopes against central differences, and points' distances to every
shape class's solid against the NumPy oracle."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from dvqp.geometry import distances
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon
from dvqp.geometry.solid import solid
from tests.common import PIPE_RADIUS
from tests.oracles.resolution import point_distances, with_height

PERIOD = 2.0 * math.pi * PIPE_RADIUS
metres = st.floats(-0.2, 0.2, allow_nan=False)


@settings(deadline=None)  # the first call compiles the kernel
@given(d2=metres, dh=metres)
def test_the_solid_distance_is_the_extruded_footprints_case_by_case(d2: float, dh: float) -> None:
    d, _, _ = solid(d2, dh)
    want = with_height(np.array([d2]), np.array([dh]), 0.0)[0]
    assert d == want or math.isclose(d, want, rel_tol=1e-15, abs_tol=1e-18)


@settings(deadline=None)  # the first call compiles the kernel
@given(d2=metres, dh=metres, step2=metres, steph=metres)
def test_it_grows_with_each_distance_at_most_as_fast(
    d2: float, dh: float, step2: float, steph: float
) -> None:
    """Nondecreasing and 1-Lipschitz in each argument: bounds of d₂ and d_h over a part bound
    its clearance to the solid."""
    d = solid(d2, dh)[0]
    moved = solid(d2 + abs(step2), dh + abs(steph))[0]
    assert d - 1e-15 <= moved <= d + abs(step2) + abs(steph) + 1e-15


@settings(deadline=None)  # the first call compiles the kernel
@given(d2=metres)
def test_an_unbounded_obstacle_is_its_footprint(d2: float) -> None:
    assert solid(d2, -math.inf) == (d2, 1.0, 0.0)


@settings(deadline=None)  # the first call compiles the kernel
@given(d2=metres, dh=metres)
def test_its_slopes_are_its_derivatives_away_from_the_edges(d2: float, dh: float) -> None:
    """Not differentiable on the top edge (d₂ = 0 = d_h) nor where d₂ = d_h inside (C¹
    elsewhere, across the faces' planes too): checked a millimetre away from both."""
    assume(math.hypot(d2, dh) > 1e-3)
    assume(not (d2 < 1e-3 and dh < 1e-3 and abs(d2 - dh) < 1e-3))
    _, w2, wh = solid(d2, dh)
    eps = 1e-9  # the curvature past the edge is 1/d: a small step
    assert math.isclose(
        w2, (solid(d2 + eps, dh)[0] - solid(d2 - eps, dh)[0]) / (2 * eps), abs_tol=1e-5
    )
    assert math.isclose(
        wh, (solid(d2, dh + eps)[0] - solid(d2, dh - eps)[0]) / (2 * eps), abs_tol=1e-5
    )
    assert math.isclose(w2 * w2 + wh * wh, 1.0, rel_tol=1e-12)  # a unit gradient


SHAPES = (
    Circle(np.array([0.2, 0.3]), 0.06, height=0.04),
    Band(0.25, 0.29, height=0.025),
    Polygon(np.array([[0.1, 0.2], [0.22, 0.21], [0.2, 0.33], [0.12, 0.3]]), height=0.012),
    Inlet(np.array([0.15, 0.28]), 0.07, PIPE_RADIUS, height=0.03),
    Circle(np.array([0.2, 0.3]), 0.06),  # unbounded: a wall to the sky
)


@settings(max_examples=60, deadline=None)
@given(
    points=st.lists(
        st.tuples(st.floats(0.0, 0.35), st.floats(0.15, 0.42), st.floats(0.0, 0.12)),
        min_size=1,
        max_size=8,
    )
)
def test_points_distances_to_each_solid_are_the_oracles(
    points: list[tuple[float, float, float]],
) -> None:
    p = np.array(points)
    d, normal = distances(SHAPES, p, PERIOD)
    np.testing.assert_allclose(d, point_distances(SHAPES, p, PERIOD), rtol=0, atol=1e-9)
    assert normal.shape == (len(SHAPES), p.shape[0], 3)
    np.testing.assert_array_equal(normal[-1, :, 2], 0.0)  # unbounded: no h part
    np.testing.assert_array_equal(d[-1], distances(SHAPES[-1:], p[:, :2], PERIOD)[0][0])


def test_the_normal_is_the_gradient_in_l_z_and_h() -> None:
    """Central differences of the distance in each of l, z, h, at points over, beside and
    past the edge of each solid, and inside."""
    rng = np.random.default_rng(3)
    p = np.column_stack(
        [rng.uniform(0.0, 0.35, 400), rng.uniform(0.15, 0.42, 400), rng.uniform(0.0, 0.12, 400)]
    )
    d, normal = distances(SHAPES, p, PERIOD)
    eps, checked = 1e-7, 0
    for c in range(3):
        step = np.zeros(3)
        step[c] = eps
        fd = (distances(SHAPES, p + step, PERIOD)[0] - distances(SHAPES, p - step, PERIOD)[0]) / (
            2 * eps
        )
        smooth = np.abs(fd - normal[..., c]) < 1e-5
        checked += int(smooth.sum())
        # where they differ, a kink lies within eps·10⁴ of the point (edges, medial lines)
        far = (np.abs(d) > 1e-3)[..., None] & (smooth[..., None] == 0)
        assert far.sum() <= 0.02 * d.size, far.sum()
    assert checked >= 0.97 * 3 * d.size


def test_the_footprints_the_halving_may_take_as_convex_are_the_convex_ones() -> None:
    """Its supporting-line bound holds only for convex footprints: dvqp's circle, band and
    inlet, and a polygon only if it is convex (an L-shaped pad is not)."""
    from dvqp.geometry.measure import ShapeArrays

    square = Polygon(np.array([[0.1, 0.2], [0.2, 0.2], [0.2, 0.3], [0.1, 0.3]]), height=0.01)
    ell = Polygon(
        np.array([[0.1, 0.2], [0.3, 0.2], [0.3, 0.25], [0.15, 0.25], [0.15, 0.4], [0.1, 0.4]]),
        height=0.01,
    )
    packed = ShapeArrays.of((*SHAPES[:4], square, ell), PERIOD)
    assert packed.convex.tolist() == [True, True, True, True, True, False]
