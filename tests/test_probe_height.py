"""The probe's height limit: it may touch the pipe surface but not go below it."""

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import ProbeHeight
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT


def test_the_row_is_minus_the_probe_height_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = ProbeHeight(floor=0.0, gain=0.5).compute(state, DT)
    fd = central_difference(
        lambda v: KinematicState.compute(robot, v, PIPE_RADIUS).tool[2], q0, 1e-7
    )
    np.testing.assert_allclose(-rows.G[0], fd, atol=1e-8)
    expected = min(0.5 / DT * state.tool[2], np.sqrt(2.0 * 1.0 * state.tool[2]))
    np.testing.assert_allclose(rows.h, [expected])
    assert rows.labels == ("probe/height",)


def test_the_excess_counts_from_the_surface(robot: Robot, q0: np.ndarray) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    high = ProbeHeight(floor=float(start.tool[2]) + 0.002)
    found = high.excess(start, start)
    assert found.value == pytest.approx(0.0, abs=1e-15)  # starts below: may stay, not worse
    assert ProbeHeight().excess(start, start).value < 0


def test_constructor_validates_the_floor() -> None:
    with pytest.raises(ParameterError, match="floor"):
        ProbeHeight(floor=float("nan"))
