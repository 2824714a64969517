"""The inlet's distances measure its exact curve: against 200 000 outline points, inside and
out, near the tips, for points and segments, and their gradients by finite differences."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from dvqp.geometry import distances, segment_distances
from dvqp.geometry.shapes import Inlet

R = 0.254
PERIOD = 2 * math.pi * R
INLETS = [
    Inlet(np.array([0.1, 0.2]), 0.075, R),
    Inlet(np.array([-0.3, 0.5]), 0.2, R),
    Inlet(np.array([0.0, 0.0]), 0.25, R),
]  # r/R 0.3, 0.79, 0.98
DENSE = 200_000


class Dense:
    """The outline as a closed polyline of ``count`` points (200 000: its chords within 0.1 µm
    of the curve) with a k-d tree of them."""

    def __init__(self, inlet: Inlet, count: int = DENSE) -> None:
        self.ring, self.count = inlet.curve(count), count
        self.tree = cKDTree(self.ring)

    def query(self, p: np.ndarray) -> tuple[np.ndarray]:
        """Distance of points (k, 2) to the polyline: to the chords either side of the
        nearest point."""
        k = self.tree.query(p)[1]
        best = np.full(p.shape[0], np.inf)
        for other in (k - 1, (k + 1) % self.count):
            a, b = self.ring[k], self.ring[other]
            t = np.clip(((p - a) * (b - a)).sum(1) / ((b - a) ** 2).sum(1), 0.0, 1.0)
            best = np.minimum(best, np.linalg.norm(p - a - t[:, None] * (b - a), axis=1))
        return (best,)


TREES = [Dense(s) for s in INLETS]
COARSE = [Dense(s, DENSE // 50) for s in INLETS]
"""The outlines at 4 000 points: a k-d tree's query from deep inside a ring visits most of
it (4 ms for the dense one), so the dense one is asked only of the points that may be nearest."""


def signed(inlet: Inlet, tree: Dense, p: np.ndarray) -> np.ndarray:
    """Signed distance of points (k, 2) to the dense outline; inside where
    ``(R sin(Δl/R))² + Δz² < r²`` and ``|Δl| < πR/2``."""
    d = tree.query(p)[0]
    off = p - inlet.center
    inside = ((R * np.sin(off[:, 0] / R)) ** 2 + off[:, 1] ** 2 < inlet.radius**2) & (
        np.abs(off[:, 0]) < 0.5 * math.pi * R
    )
    return np.where(inside, -d, d)


def least(k: int, p: np.ndarray) -> float:
    """The least signed distance (m) of points (k, 2) to inlet ``k``'s dense outline: found
    among the points within 0.1 mm of the least on the coarse one, whose chords stray from
    the curve by far less (κ c²/8 with chords c of 0.4 mm: 20 µm at a 1 mm radius of
    curvature; 0.44 µm measured against the dense one)."""
    p = np.unique(p, axis=0)  # a segment of length 0 is one point
    rough = signed(INLETS[k], COARSE[k], p)
    return float(signed(INLETS[k], TREES[k], p[rough <= rough.min() + 1e-4]).min())


def place(inlet: Inlet, u: float, v: float, tip: bool) -> np.ndarray:
    """A point in the inlet's box grown by half (``u, v`` in [−1, 1]), or within 5 mm of a
    tip (where the curvature is largest)."""
    half_l = R * math.asin(inlet.radius / R)
    if tip:
        return inlet.center + np.array([math.copysign(half_l, u) + 0.005 * v, 0.005 * u])
    return inlet.center + np.array([1.5 * half_l * u, 1.5 * inlet.radius * v])


unit = st.floats(-1.0, 1.0)
PLACES = st.tuples(st.integers(0, len(INLETS) - 1), unit, unit, st.booleans())


@settings(max_examples=300, deadline=None)
@given(st.lists(PLACES, min_size=1, max_size=20))
def test_the_point_distance_is_the_exact_curve_s_to_a_micrometre(found: list) -> None:
    for which in range(len(INLETS)):
        pts = np.array([place(INLETS[k], u, v, tip) for k, u, v, tip in found if k == which])
        if not pts.size:
            continue
        d, n = distances([INLETS[which]], pts, PERIOD)
        want = signed(INLETS[which], TREES[which], pts)
        np.testing.assert_allclose(d[0], want, rtol=0, atol=1e-6)
        closest = pts - d[0][:, None] * n[0]  # the nearest outline point, on the curve
        np.testing.assert_allclose(TREES[which].query(closest)[0], 0.0, atol=1e-6)


SEGMENTS = st.tuples(PLACES, unit, unit, st.floats(0.0, 0.3))


@settings(max_examples=40, deadline=None)
@given(st.lists(SEGMENTS, min_size=1, max_size=8))
@example([((2, 0.342, 0.0, True), 0.0, -0.327, 0.228)])  # along l = the tip's: touches it
def test_the_segment_distance_is_the_least_along_the_segment_to_a_micrometre(
    found: list,
) -> None:
    ts = np.linspace(0.0, 1.0, 2001)[:, None]
    for (k, u, v, tip), du, dv, length in found:
        inlet, tree = INLETS[k], TREES[k]
        start = place(inlet, u, v, tip)
        end = start + length * np.array([du, dv])
        d, t, n = (x[0, 0] for x in segment_distances([inlet], start[None], end[None], PERIOD))
        sampled = least(k, start + ts * (end - start))
        step = length * math.hypot(du, dv) / 2000  # how far the best sample may be from it
        assert sampled - step - 1e-6 <= d <= sampled + 1e-6
        at = start + t * (end - start)
        assert abs(signed(inlet, tree, at[None])[0] - d) <= 1e-6  # t is where it is
        d_at, n_at = distances([inlet], at[None], PERIOD)
        assert abs(d_at[0, 0] - d) <= 1e-9
        assert d <= 1e-9 or np.allclose(n_at[0, 0], n, atol=1e-6)  # else a medial axis, or rounding


def test_a_segment_that_crosses_with_both_ends_outside_enters() -> None:
    inlet = INLETS[0]
    half_l = R * math.asin(inlet.radius / R)
    a = inlet.center + np.array([[-2 * half_l, 0.01]])
    b = inlet.center + np.array([[2 * half_l, 0.02]])
    d, t, _ = segment_distances([inlet], a, b, PERIOD)
    assert d[0, 0] < -0.05 and 0.3 < t[0, 0] < 0.7
    beyond = inlet.center + np.array([[1.2 * half_l, 0.0]])  # the line crosses, it stops short
    d, t, _ = segment_distances([inlet], beyond + np.array([[0.05, 0.0]]), beyond, PERIOD)
    assert t[0, 0] == 1.0 and abs(d[0, 0] - 0.2 * half_l) < 1e-9


@settings(max_examples=60, deadline=None)
@given(PLACES, unit, unit)
@example((2, 0.0, 1.0, True), 0.0, 1e-300)  # a segment of 1e-301 m: a point
@example((0, -6.103515625e-05, 0.0, True), 0.0, 0.0)  # 30 µm off a tip (CI)
def test_the_gradients_are_the_finite_differences(a: tuple, du: float, dv: float) -> None:
    k, u, v, tip = a
    inlet = INLETS[k]
    p = place(inlet, u, v, tip)
    q = p + 0.08 * np.array([du, dv])
    h = 1e-7
    d0, n = distances([inlet], p[None], PERIOD)
    # the normal is (p − closest point) / d: a closest point found to ~1e-9 m turns it by up to
    # 1e-9 / d (30 µm outside a tip: 2.3e-5), capped at 1 mrad on the outline itself
    tolerance = 1e-5 + min(1e-3, 1e-9 / max(abs(float(d0[0, 0])), 1e-12))
    d, t, nseg = (x[0, 0] for x in segment_distances([inlet], p[None], q[None], PERIOD))
    for axis in range(2):
        e = np.zeros(2)
        e[axis] = h
        fd = (
            distances([inlet], (p + e)[None], PERIOD)[0]
            - distances([inlet], (p - e)[None], PERIOD)[0]
        )[0, 0] / (2 * h)
        on_tip = tip and abs(float(d0[0, 0])) < 1e-9  # on a tip's kink: no gradient there
        assert abs(fd - n[0, 0, axis]) < tolerance or _kinked(inlet, p) or on_tip
        e_hat = np.array([du, dv]) / max(math.hypot(du, dv), 1e-300)
        turning = t in (0.0, 1.0) and abs(nseg @ e_hat) < 0.05  # an end about to give way
        if d > 1e-4 and math.hypot(du, dv) > 0.01 and not turning:  # ∂d/∂a = (1 − t) n
            up = segment_distances([inlet], (p + e)[None], q[None], PERIOD)[0][0, 0]
            down = segment_distances([inlet], (p - e)[None], q[None], PERIOD)[0][0, 0]
            fa = (up - down) / (2 * h)
            assert abs(fa - (1 - t) * nseg[axis]) < 1e-4


def _kinked(inlet: Inlet, p: np.ndarray) -> bool:
    """On (near) the medial axis inside, where the distance has a kink: the centre lines."""
    off = np.abs(p - inlet.center)
    return bool(distances([inlet], p[None], PERIOD)[0][0, 0] < 0 and off.min() < 1e-4)
