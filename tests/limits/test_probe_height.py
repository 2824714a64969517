"""The probe's height limit: it may touch the pipe surface but not go below it."""

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import ProbeHeight, SurfaceHeight
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT, configurations, damper_rows
from tests.oracles.limits import assert_excess, chord_low, worst_excess


def holder_low(robot: Robot, q: np.ndarray) -> float:
    """Height of the lowest point of the probe holder (last body point to the tool), m."""
    o = np.asarray(KinematicState.compute(robot, q, PIPE_RADIUS).origins)
    return chord_low(o[4], o[5], PIPE_RADIUS)[0]


def test_the_rows_are_minus_the_probe_and_holder_height_gradients(
    robot: Robot, q0: np.ndarray
) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = stepping.rows(ProbeHeight(floor=0.0, gain=0.5), robot, q0)
    assert rows.labels == ("probe/height", "holder/height")  # type: ignore[union-attr]
    probe = central_difference(
        lambda v: KinematicState.compute(robot, v, PIPE_RADIUS).tool[2], q0, 1e-7
    )
    holder = central_difference(lambda v: holder_low(robot, v), q0, 1e-7)
    np.testing.assert_allclose(-rows.G, [probe, holder], atol=1e-8)  # type: ignore[union-attr]
    low = holder_low(robot, q0)
    assert low < state.tool[2] - 1e-3  # the holder dips below the probe (and point 5)
    heights = np.array([state.tool[2], low])
    expected = np.minimum(0.5 / DT * heights, np.sqrt(2.0 * 1.0 * heights))
    np.testing.assert_allclose(rows.h, expected)  # type: ignore[union-attr]


def test_the_probe_and_the_body_points_keep_their_own_heights(robot: Robot, q0: np.ndarray) -> None:
    limits = [SurfaceHeight(min_height=0.05, gain=0.4), ProbeHeight(floor=0.01, gain=0.7)]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    for q in [q0, *configurations(robot, q0, 3, seed=22, spread=0.1)]:
        body, probe = (damper_rows(s, limit, q, fd=q is q0) for limit in limits)
        assert body.labels[:5] == tuple(f"point{i}/height" for i in range(1, 6))
        assert probe.labels[0] == "probe/height"
        assert s.problem().G.shape[0] == 5 + 4 + 1 + 2  # points, links, carriage; probe, holder


def test_the_excess_counts_from_the_surface(robot: Robot, q0: np.ndarray) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    high = ProbeHeight(floor=float(start.tool[2]) + 0.002)
    found = stepping.excess([high], robot, q0, q0)
    assert found.value == pytest.approx(0.0, abs=1e-15)  # starts below: may stay, not worse
    assert not found.broken
    kept = stepping.excess([ProbeHeight()], robot, q0, q0)
    lowest = min(float(start.tool[2]), holder_low(robot, q0))  # the holder's low point
    assert kept.value == pytest.approx(-lowest, abs=1e-12)  # its height is room
    lower = q0.copy()
    lower[12] -= 0.3  # swing the probe down
    moved = KinematicState.compute(robot, lower, PIPE_RADIUS)
    assert moved.tool[2] < start.tool[2] - 1e-3
    found = stepping.excess([high], robot, q0, lower)  # below where it started: broken
    assert found.broken and (found.quantity, found.unit) == ("height", "m")
    assert_excess(found, worst_excess([high], start, moved))


def test_constructor_validates_the_floor() -> None:
    with pytest.raises(ParameterError, match="floor"):
        ProbeHeight(floor=float("nan"))
    with pytest.raises(ParameterError, match="gain"):
        ProbeHeight(gain=2.0)
