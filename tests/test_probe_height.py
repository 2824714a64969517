"""The probe's height limit: it may touch the pipe surface but not go below it."""

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import ProbeHeight, SurfaceHeight
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT, configurations, damper_rows


def test_the_row_is_minus_the_probe_height_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = stepping.rows(ProbeHeight(floor=0.0, gain=0.5), robot, q0)
    fd = central_difference(
        lambda v: KinematicState.compute(robot, v, PIPE_RADIUS).tool[2], q0, 1e-7
    )
    np.testing.assert_allclose(-rows.G[0], fd, atol=1e-8)  # type: ignore[union-attr]
    expected = min(0.5 / DT * state.tool[2], np.sqrt(2.0 * 1.0 * state.tool[2]))
    np.testing.assert_allclose(rows.h, [expected])  # type: ignore[union-attr]
    assert rows.labels == ("probe/height",)  # type: ignore[union-attr]


def test_the_probe_and_the_body_points_keep_their_own_heights(robot: Robot, q0: np.ndarray) -> None:
    limits = [SurfaceHeight(min_height=0.05, gain=0.4), ProbeHeight(floor=0.01, gain=0.7)]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    for q in [q0, *configurations(robot, q0, 3, seed=22, spread=0.1)]:
        body, probe = (damper_rows(s, limit, q, fd=q is q0) for limit in limits)
        assert body.rows == 5 and probe.labels == ("probe/height",)
        assert s.problem().G.shape[0] == 6


def test_the_excess_counts_from_the_surface(robot: Robot, q0: np.ndarray) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    high = ProbeHeight(floor=float(start.tool[2]) + 0.002)
    found = stepping.excess([high], robot, q0, q0)
    assert found.value == pytest.approx(0.0, abs=1e-15)  # starts below: may stay, not worse
    assert not found.broken
    kept = stepping.excess([ProbeHeight()], robot, q0, q0)
    assert kept.value == pytest.approx(-float(start.tool[2]), abs=1e-15)  # its height is room
    lower = q0.copy()
    lower[12] -= 0.3  # swing the probe down
    moved = KinematicState.compute(robot, lower, PIPE_RADIUS)
    assert moved.tool[2] < start.tool[2] - 1e-3
    found = stepping.excess([high], robot, q0, lower)  # below where it started: broken
    assert found.broken and found.label == "probe/height"
    assert (found.quantity, found.unit) == ("height", "m")
    assert found.value == pytest.approx(start.tool[2] - moved.tool[2], abs=1e-12)
    assert found.actual == pytest.approx(moved.tool[2], abs=1e-12)
    assert found.bound == pytest.approx(start.tool[2], abs=1e-12)


def test_constructor_validates_the_floor() -> None:
    with pytest.raises(ParameterError, match="floor"):
        ProbeHeight(floor=float("nan"))
    with pytest.raises(ParameterError, match="gain"):
        ProbeHeight(gain=2.0)
