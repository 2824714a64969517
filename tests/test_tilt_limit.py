"""The tilt limit: the probe axis kept away from the radial direction, so α stays defined."""

import math

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import TiltLimit, tilt, tilt_cosine, tilt_sine
from tests.common import PIPE_RADIUS, central_difference, random_configurations
from tests.limit_fixtures import DT


def test_the_tilt_row_is_minus_the_gradient_of_sin_tilt(robot: Robot) -> None:
    limit = TiltLimit(min_tilt=0.2)

    def sine(q: np.ndarray) -> float:
        return tilt_sine(KinematicState.compute(robot, q, PIPE_RADIUS))

    for q in random_configurations(6, seed=31, spread=0.5):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        rows = limit.compute(state, DT)
        assert rows.labels == ("probe/tilt",)
        np.testing.assert_allclose(-rows.G[0], central_difference(sine, q, 1e-7), atol=1e-6)


def test_the_cosine_row_is_the_derivative_of_the_cosine(robot: Robot) -> None:
    def cosine(q: np.ndarray) -> float:
        return tilt_cosine(KinematicState.compute(robot, q, PIPE_RADIUS))[0]

    for q in random_configurations(4, seed=32, spread=0.5):
        row = tilt_cosine(KinematicState.compute(robot, q, PIPE_RADIUS))[1]
        np.testing.assert_allclose(row, central_difference(cosine, q, 1e-7), atol=1e-7)


def test_tilt_is_measured_from_the_frames(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    o, a = state.origins[-1], state.axes[-1]
    radial = np.array([o[0], o[1], 0.0]) / math.hypot(o[0], o[1])
    assert tilt(state) == pytest.approx(math.acos(a @ radial), abs=1e-12)
    assert tilt_sine(state) == pytest.approx(math.sin(tilt(state)), abs=1e-12)


def test_the_right_hand_side_damps_toward_the_minimum_tilt(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = TiltLimit(min_tilt=0.3, gain=0.4, deceleration=math.inf).compute(state, DT)
    expected = 0.4 / DT * (tilt_sine(state) - math.sin(0.3))
    np.testing.assert_allclose(rows.h, [expected])


def test_a_zero_minimum_turns_the_limit_off(robot: Robot, state0: KinematicState) -> None:
    limit = TiltLimit(min_tilt=0.0)
    assert limit.compute(state0, DT).rows == 0
    assert not limit.excess(state0, state0).broken


def test_the_excess_is_in_radians_from_the_start_or_the_minimum(
    robot: Robot, q0: np.ndarray
) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    limit = TiltLimit(min_tilt=0.2)
    assert limit.excess(start, start).value < 0  # far from radial
    strict = TiltLimit(min_tilt=1.5)  # the start is already closer to radial than 1.5 rad
    found = strict.excess(start, start)
    assert found.value == pytest.approx(0.0, abs=1e-12) and not found.broken


def test_constructor_validates_the_minimum() -> None:
    with pytest.raises(ParameterError, match="min_tilt"):
        TiltLimit(min_tilt=-0.1)
    with pytest.raises(ParameterError, match="min_tilt"):
        TiltLimit(min_tilt=2.0)
