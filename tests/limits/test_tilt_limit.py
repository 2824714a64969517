"""The tilt limit: the probe axis kept away from the radial direction, so α stays defined."""

import math

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import TiltLimit
from dvqp.limits.tilt import tilt_angle, tilt_cosine
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference, random_configurations
from tests.limit_fixtures import DT, damper_rows, problem_rows
from tests.oracles.limits import tilt, tilt_sine


def test_the_tilt_row_is_minus_the_gradient_of_sin_tilt(robot: Robot) -> None:
    limit = TiltLimit(min_tilt=0.2)
    configurations = random_configurations(6, seed=31, spread=0.5)
    s = stepping.stepper(robot, configurations[0], limits=[limit], backend="daqp")

    def sine(q: np.ndarray) -> float:
        return tilt_sine(KinematicState.compute(robot, q, PIPE_RADIUS))

    for q in configurations:
        rows = damper_rows(s, limit, q)  # labels, h, G by the formula
        assert rows.labels == ("probe/tilt",)
        np.testing.assert_allclose(-rows.G[0], central_difference(sine, q, 1e-7), atol=1e-6)


def test_the_cosine_row_is_the_derivative_of_the_cosine(robot: Robot) -> None:
    def cosine(q: np.ndarray) -> float:
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        o, a = state.origins[state.k], state.axes[state.k]
        return float(a[0] * o[0] + a[1] * o[1]) / math.hypot(o[0], o[1])

    for q in random_configurations(4, seed=32, spread=0.5):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        row = np.zeros(13)
        u = tilt_cosine(state.origins, state.axes, state.frame_jacobians, state.k, row)
        assert u == pytest.approx(cosine(q), abs=1e-15)
        np.testing.assert_allclose(row, central_difference(cosine, q, 1e-7), atol=1e-7)


def test_tilt_is_measured_from_the_frames(robot: Robot) -> None:
    for q in random_configurations(6, seed=33, spread=1.0):
        state = KinematicState.compute(robot, q, PIPE_RADIUS)
        o, a = state.origins[state.k], state.axes[state.k]
        radial = np.array([o[0], o[1], 0.0]) / math.hypot(o[0], o[1])
        assert tilt_angle(state.origins, state.axes, state.k) == pytest.approx(
            math.acos(a @ radial), abs=1e-12
        )
        assert tilt_sine(state) == pytest.approx(math.sin(tilt(state)), abs=1e-12)


def test_the_right_hand_side_damps_toward_the_minimum_tilt(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = stepping.rows(TiltLimit(min_tilt=0.3, gain=0.4, deceleration=math.inf), robot, q0)
    expected = 0.4 / DT * (tilt_sine(state) - math.sin(0.3))
    np.testing.assert_allclose(rows.h, [expected])  # type: ignore[union-attr]
    braked = stepping.rows(TiltLimit(min_tilt=0.3, gain=0.4, deceleration=2.0), robot, q0)
    cap = math.sqrt(2.0 * 2.0 * (tilt_sine(state) - math.sin(0.3)))
    np.testing.assert_allclose(braked.h, [min(expected, cap)])  # type: ignore[union-attr]


def test_several_tilt_limits_each_keep_their_own_minimum(robot: Robot, q0: np.ndarray) -> None:
    limits = [TiltLimit(0.3, gain=0.2), TiltLimit(1.4, gain=0.9, deceleration=0.1)]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    for q in random_configurations(4, seed=34, spread=0.3):
        rows = [damper_rows(s, limit, q, 0.01) for limit in limits]
        assert [r.labels for r in rows] == [("probe/tilt",), ("probe/tilt",)]
        np.testing.assert_array_equal(rows[0].G, rows[1].G)  # the same distance
        assert rows[0].h[0] != rows[1].h[0]


def test_a_zero_minimum_turns_the_limit_off(robot: Robot, q0: np.ndarray) -> None:
    limit = TiltLimit(min_tilt=0.0)
    s = stepping.stepper(robot, q0, limits=[limit], backend="daqp")
    s.prepare(np.zeros(4), DT)
    assert s.problem().G is None and problem_rows(s) == 0
    q = q0.copy()
    q[12] += 1.5  # the probe almost radial: nothing to keep
    assert s.load(q) and not s.broken
    assert s.excess().value == -math.inf


def test_the_excess_is_in_radians_from_the_start_or_the_minimum(
    robot: Robot, q0: np.ndarray
) -> None:
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    kept = stepping.excess([TiltLimit(min_tilt=0.2)], robot, q0, q0)
    assert kept.value == pytest.approx(0.2 - tilt(start), abs=1e-12)  # far from radial
    strict = TiltLimit(min_tilt=1.5)  # the start is already closer to radial than 1.5 rad
    found = stepping.excess([strict], robot, q0, q0)
    assert found.value == pytest.approx(0.0, abs=1e-12) and not found.broken
    q = q0.copy()
    q[12] += 0.5  # toward radial
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    found = stepping.excess([strict], robot, q0, q)
    assert found.broken and found.label == "probe/tilt"
    assert (found.quantity, found.unit, found.tolerance) == ("tilt", "rad", 1e-3)
    assert found.value == pytest.approx(tilt(start) - tilt(moved), abs=1e-12)
    assert found.actual == pytest.approx(tilt(moved), abs=1e-12)
    assert found.bound == pytest.approx(tilt(start), abs=1e-12)


def test_the_tilt_is_folded_into_zero_to_a_right_angle(robot: Robot, q0: np.ndarray) -> None:
    """Past a right angle the axis nears the radial direction again (pointing outward): the
    verified tilt is ``π − θ`` there."""
    start = KinematicState.compute(robot, q0, PIPE_RADIUS)
    q = q0.copy()
    q[12] -= 0.5
    moved = KinematicState.compute(robot, q, PIPE_RADIUS)
    assert tilt(moved) > 0.5 * math.pi
    found = stepping.excess([TiltLimit(min_tilt=1.5)], robot, q0, q)
    assert found.actual == pytest.approx(math.pi - tilt(moved), abs=1e-12)
    assert found.value == pytest.approx(tilt(start) - (math.pi - tilt(moved)), abs=1e-12)
    assert found.broken


def test_constructor_validates_the_minimum() -> None:
    with pytest.raises(ParameterError, match="min_tilt"):
        TiltLimit(min_tilt=-0.1)
    with pytest.raises(ParameterError, match="min_tilt"):
        TiltLimit(min_tilt=2.0)
