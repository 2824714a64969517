"""A link's true developed-view image against the straight DV segment dvqp measures.

The real link is a straight 3-D segment; its DV image bends in ``l``. ``link_bends`` gives the
farthest it strays (``δ``), so the true clearance is at least the straight segment's less
``δ`` (a signed distance is 1-Lipschitz). Both checked on sampled real links.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.geometry import link_bends, proximity
from dvqp.geometry.bend import link_bend
from dvqp.workspace import link_ends
from tests.common import PIPE_RADIUS, random_configurations
from tests.oracles.limits import bend
from tests.oracles.resolution import point_distances
from tests.runs import scene


def real_image(a: np.ndarray, b: np.ndarray, radius: float, samples: int = 4001) -> np.ndarray:
    """``[l, z]`` (m) of the real link ``a → b`` sampled, ``l`` continued from ``a``'s."""
    t = np.linspace(0.0, 1.0, samples)[:, None]
    p = a + t * (b - a)
    return np.column_stack([radius * np.unwrap(np.arctan2(p[:, 1], p[:, 0])), p[:, 2]])


def test_the_closed_form_is_the_largest_departure_found_by_search() -> None:
    rng = np.random.default_rng(7)
    for _ in range(300):
        rho, phi = rng.uniform(0.15, 0.45, 2), rng.uniform(-math.pi, math.pi)
        span = rng.uniform(-1.5, 1.5) * rng.choice([1.0, 1e-3])
        a = np.array([rho[0] * math.cos(phi), rho[0] * math.sin(phi), 0.0])
        b = np.array([rho[1] * math.cos(phi + span), rho[1] * math.sin(phi + span), 0.1])
        g, t = link_bend(a[0], a[1], b[0], b[1])
        want, at = bend(a, b)
        assert g == pytest.approx(want, abs=1e-12)
        if abs(want) > 1e-9:
            assert t == pytest.approx(at, abs=1e-6)


def test_a_link_along_the_pipe_does_not_bend() -> None:
    assert link_bend(0.3, 0.0, 0.3, 0.0) == (0.0, 0.0)  # the same angle: z only


def test_the_real_link_lies_within_its_bend_of_the_straight_segment(robot: Robot) -> None:
    attained = 0.0
    for q in random_configurations(8, seed=5, spread=0.4):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        delta, o = link_bends(state), np.asarray(state.origins)
        for i, (a, b) in enumerate(link_ends(state.k, state.rail)):
            image = real_image(o[a], o[b], PIPE_RADIUS)
            straight = image[0] + np.linspace(0.0, 1.0, image.shape[0])[:, None] * (
                image[-1] - image[0]
            )
            away = np.abs(image[:, 0] - straight[:, 0]).max()  # z agrees at every t
            np.testing.assert_allclose(image[:, 1], straight[:, 1], rtol=0, atol=1e-15)
            assert away <= delta[i] + 1e-12 and away >= delta[i] - 1e-9
            attained = max(attained, delta[i])
    assert attained > 1e-3  # some link of the arm bends by more than a millimetre


def test_the_real_link_keeps_the_straight_clearance_less_its_bend() -> None:
    s = scene("carriage-clamp")
    radius, period = s.pipe_radius, 2 * math.pi * s.pipe_radius
    for q in random_configurations(6, seed=11, spread=0.3):
        state = KinematicState.compute(s.robot, s.q0 + 0.3 * (q - s.q0), radius)
        straight = proximity(state, s.obstacles).links.distance  # the straight DV segments (J, L)
        delta, o = link_bends(state), np.asarray(state.origins)
        for i, (a, b) in enumerate(link_ends(state.k, state.rail)):
            true = point_distances(s.obstacles, real_image(o[a], o[b], radius), period)
            true = true.min(axis=1)  # (J,)
            assert (true >= straight[:, i] - delta[i] - 1e-9).all()
            assert (true <= straight[:, i] + delta[i] + 1e-6).all()
