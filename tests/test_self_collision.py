"""Self-collision: exact 3-D segment distances and damper rows against finite differences."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import SelfCollision, self_distance
from dvqp.limits.self_collision import link_pairs, pair_distances
from tests.common import PIPE_RADIUS, central_difference, random_configurations

DT = 0.01


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_closest_points_are_no_farther_than_any_pair_of_samples(seed: int, parallel: bool) -> None:
    rng = np.random.default_rng(seed)
    p1, q1, p2 = (rng.normal(size=(1, 3)) for _ in range(3))
    q2 = p2 + 0.7 * (q1 - p1) if parallel else rng.normal(size=(1, 3))
    chain = np.vstack([p1, q1, p2, q2])  # segments 0 → 1 and 2 → 3
    dist, _, s, t = pair_distances(chain, np.array([0]), np.array([2]))
    best = np.linalg.norm((p1 + s[:, None] * (q1 - p1)) - (p2 + t[:, None] * (q2 - p2)))
    assert dist[0] == pytest.approx(best, abs=1e-12)
    g = np.linspace(0, 1, 301)[:, None]
    a, b = p1 + g * (q1 - p1), p2 + g * (q2 - p2)
    brute = np.sqrt(((a[:, None] - b[None]) ** 2).sum(-1)).min()
    assert best <= brute + 1e-12 and best >= brute - 0.01 * np.linalg.norm(q1 - p1)


def test_pairs_are_the_non_adjacent_links() -> None:
    i, j = link_pairs(5)
    assert list(zip(i.tolist(), j.tolist(), strict=True)) == [
        (0, 2), (0, 3), (0, 4), (1, 3), (1, 4), (2, 4)
    ]  # fmt: skip


def test_rows_are_minus_the_gradient_of_the_link_distances(robot: Robot) -> None:
    limit = SelfCollision(margin=0.02, influence=10.0)  # every pair gets a row
    for q in random_configurations(3, seed=41, spread=0.8):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        rows = limit.compute(state, DT)
        assert rows.rows == 6

        def distances(v: np.ndarray) -> np.ndarray:
            return limit.all_distances(KinematicState.compute(robot, v, PIPE_RADIUS)).value

        np.testing.assert_allclose(-rows.G, central_difference(distances, q, 1e-7), atol=2e-6)


def test_the_smallest_distance_names_its_pair(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    d, pair = self_distance(state)
    assert d == pytest.approx(SelfCollision().all_distances(state).value.min())
    assert pair.count("/") == 1 and pair.startswith("link")


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="margin"):
        SelfCollision(margin=-0.01)
    with pytest.raises(ParameterError, match="influence"):
        SelfCollision(influence=0.0)
