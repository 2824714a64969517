"""Self-collision: exact 3-D segment distances and damper rows against finite differences."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp import KinematicState, PartNames, Robot
from dvqp.errors import ParameterError
from dvqp.limits import SelfCollision, self_distance
from dvqp.limits.self_collision import pair_distances
from dvqp.workspace import PairBuffers, as_struct
from tests import stepping
from tests.common import PIPE_RADIUS, random_configurations
from tests.limit_fixtures import damper_rows
from tests.oracles.limits import segment_distance, self_distances

DT = 0.01


def closest(chain: np.ndarray) -> PairBuffers:
    """The compiled closest points of the segments 0 → 1 and 2 → 3 of ``chain`` (4, 3)."""
    pairs = PairBuffers.allocate(3)  # three links: the one pair (0, 2)
    assert (pairs.i.tolist(), pairs.j.tolist()) == ([0], [2])
    pair_distances(np.ascontiguousarray(chain), as_struct(pairs))
    return pairs


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10_000), st.booleans())
def test_closest_points_are_no_farther_than_any_pair_of_samples(seed: int, parallel: bool) -> None:
    rng = np.random.default_rng(seed)
    p1, q1, p2 = (rng.normal(size=(1, 3)) for _ in range(3))
    q2 = p2 + 0.7 * (q1 - p1) if parallel else rng.normal(size=(1, 3))
    pairs = closest(np.vstack([p1, q1, p2, q2]))  # segments 0 → 1 and 2 → 3
    s, t = pairs.s[0], pairs.t[0]
    assert 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0
    gap = (p1 + s * (q1 - p1)) - (p2 + t * (q2 - p2))
    best = np.linalg.norm(gap)
    assert pairs.distance[0] == pytest.approx(best, abs=1e-12)
    np.testing.assert_allclose(pairs.normal[0] * best, gap[0], atol=1e-12)
    g = np.linspace(0, 1, 301)[:, None]
    a, b = p1 + g * (q1 - p1), p2 + g * (q2 - p2)
    brute = np.sqrt(((a[:, None] - b[None]) ** 2).sum(-1)).min()
    assert best <= brute + 1e-12 and best >= brute - 0.01 * np.linalg.norm(q1 - p1)
    searched, _ = segment_distance(p1, q1, p2, q2)  # a golden-section search on s
    assert best == pytest.approx(searched[0], abs=1e-10)


def test_degenerate_segments_are_points() -> None:
    a, c, d = np.array([0.0, 0.0, 0.0]), np.array([1.0, -1.0, 0.5]), np.array([1.0, 1.0, 0.5])
    pairs = closest(np.vstack([a, a, c, d]))  # the first link has no length
    assert pairs.s[0] == 0.0 and pairs.t[0] == pytest.approx(0.5)
    assert pairs.distance[0] == pytest.approx(np.hypot(1.0, 0.5), abs=1e-15)
    pairs = closest(np.vstack([a, a, c, c]))  # both
    assert pairs.distance[0] == pytest.approx(np.linalg.norm(c - a), abs=1e-15)


def test_pairs_are_the_non_adjacent_links() -> None:
    pairs = PairBuffers.allocate(5)
    assert list(zip(pairs.i.tolist(), pairs.j.tolist(), strict=True)) == [
        (0, 2),
        (0, 3),
        (0, 4),
        (1, 3),
        (1, 4),
        (2, 4),
    ]
    assert SelfCollision().labels(PartNames.numbered(5)) == (
        "link1/link3",
        "link1/link4",
        "link1/holder",
        "link2/link4",
        "link2/holder",
        "link3/holder",
    )
    railed = PairBuffers.allocate(5, rail=True)  # the carriage link (5) against all but link1
    pairs = list(zip(railed.i.tolist(), railed.j.tolist(), strict=True))
    assert [p for p in pairs if 5 in p] == [(1, 5), (2, 5), (3, 5), (4, 5)] and len(pairs) == 10
    assert SelfCollision().labels(PartNames.numbered(5, rail=True))[-1] == "holder/carriage"


def test_rows_are_minus_the_gradient_of_the_link_distances(robot: Robot) -> None:
    """Every pair gets a row; ``G`` against central differences of brute-force distances."""
    limit = SelfCollision(margin=0.02, influence=10.0)
    configurations = random_configurations(3, seed=41, spread=0.8)
    s = stepping.stepper(robot, configurations[0], limits=[limit], backend="daqp", dt=DT)
    for q in configurations:
        rows = damper_rows(s, limit, q, DT, atol=1e-9)  # h to the search's precision
        assert rows.rows == 10  # 6 pairs of body links and holder, 4 with the carriage link


def test_only_pairs_within_the_margin_plus_influence_add_rows(robot: Robot) -> None:
    configurations = random_configurations(8, seed=42, spread=1.0)
    state = KinematicState.compute(robot, configurations[0], PIPE_RADIUS)
    d = np.sort(self_distances(np.array(state.origins), state.k))  # pairs often tie (equal links)
    gaps = np.flatnonzero(np.diff(d) > 2e-3)
    low, high = (0.5 * (d[g] + d[g + 1]) for g in gaps[:2])
    limits = [
        SelfCollision(margin=0.01, influence=high - 0.01, gain=0.3),
        SelfCollision(margin=low - 1e-3, influence=1e-3, deceleration=np.inf),
    ]
    s = stepping.stepper(robot, configurations[0], limits=limits, backend="daqp", dt=DT)
    counts = [damper_rows(s, limit, configurations[0], DT, atol=1e-9).rows for limit in limits]
    assert counts == [np.sum(d < high), np.sum(d < low)] and counts[0] > counts[1] > 0
    counts = [damper_rows(s, limits[0], q, DT, atol=1e-9).rows for q in configurations]
    assert len(set(counts)) > 1  # rows come and go as the pairs move


def test_the_smallest_distance_names_its_pair(robot: Robot) -> None:
    names = SelfCollision().labels(robot.part_names)
    for q in random_configurations(4, seed=43, spread=0.8):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        d, pair = self_distance(state)
        brute = self_distances(np.array(state.origins), state.k)
        assert d == pytest.approx(brute.min(), abs=1e-12)
        assert brute[names.index(pair)] == pytest.approx(d, abs=1e-12)  # pairs may tie


def test_the_excess_names_the_pair_that_folded_closer_than_at_the_start(robot: Robot) -> None:
    start, q = random_configurations(2, seed=44, spread=0.8)

    def distances(v: np.ndarray) -> np.ndarray:
        return self_distances(np.array(KinematicState.compute(robot, v, PIPE_RADIUS).origins), 5)

    at_start, at_q = distances(start), distances(q)
    margin = float(np.max(at_start)) + 0.01  # every pair starts inside: its start is its floor
    found = stepping.excess([SelfCollision(margin=margin)], robot, start, q)
    over = at_start - at_q
    assert found.value == pytest.approx(over.max(), abs=1e-12) and found.value > 0
    assert found.quantity == "self distance" and found.unit == "m"
    assert over[SelfCollision().labels(robot.part_names).index(found.label)] == pytest.approx(
        found.value
    )


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="margin"):
        SelfCollision(margin=-0.01)
    with pytest.raises(ParameterError, match="margin"):
        SelfCollision(margin=np.inf)
    with pytest.raises(ParameterError, match="influence"):
        SelfCollision(influence=0.0)
