"""Surface height: one damper row per body point and per body link's lowest point, minus the
height gradient; the damper rule."""

import math

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import SurfaceHeight, damper_value
from tests import stepping
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT, configurations, damper_rows
from tests.oracles.limits import chord_low


def body_lows(robot: Robot, q: np.ndarray) -> np.ndarray:
    """The body points' heights, then the lowest point of each body link's chord, m."""
    o = np.asarray(KinematicState.compute(robot, q, PIPE_RADIUS).origins)
    lows = [chord_low(o[i], o[i + 1], PIPE_RADIUS)[0] for i in range(4)]
    return np.concatenate([KinematicState.compute(robot, q, PIPE_RADIUS).points[:, 2], lows])


def test_height_rows_are_minus_the_height_gradient(robot: Robot, q0: np.ndarray) -> None:
    rows = stepping.rows(SurfaceHeight(min_height=0.02, gain=0.5), robot, q0)
    labels = rows.labels  # type: ignore[union-attr]
    names = (*(f"point{i}/height" for i in range(1, 6)), *(f"link{i}/height" for i in range(1, 5)))
    assert labels[:5] == names[:5] and set(labels) <= set(names)  # chords: where they dip
    on = [names.index(label) for label in labels]
    assert len(on) > 5  # at q0 some links dip below their ends
    fd = central_difference(lambda v: body_lows(robot, v), q0, 1e-7)[on]
    np.testing.assert_allclose(-rows.G, fd, rtol=1e-6, atol=1e-8)  # type: ignore[union-attr]
    room = body_lows(robot, q0)[on] - 0.02
    np.testing.assert_allclose(rows.h, np.minimum(0.5 / DT * room, np.sqrt(2.0 * room)))  # type: ignore[union-attr]


def test_a_point_well_below_the_minimum_may_only_not_descend(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    above = float(state0.points[:, 2].max()) + 0.01
    rows = stepping.rows(SurfaceHeight(min_height=above, gain=0.5), robot, q0)
    assert rows.rows >= 5  # type: ignore[union-attr]
    np.testing.assert_array_equal(rows.h, 0.0)  # type: ignore[union-attr]


def test_the_damper_rule_decays_brakes_pulls_small_drifts_back_and_holds_deep_starts() -> None:
    d = [0.05, 0.01, 0.00995, -0.02]

    def rule(deceleration: float) -> list[float]:
        return [damper_value(x, 0.01, 0.5, 0.1, 1e-4, deceleration) for x in d]

    # 4 cm above: decay; at the margin: 0; 0.05 mm below: pulled back; 3 cm below: held
    np.testing.assert_allclose(rule(math.inf), [0.2, 0.0, -0.00025, 0.0], atol=1e-15)
    # with a deceleration of 0.2 m/s², 4 cm away: at most sqrt(2·0.2·0.04) = 0.126 m/s;
    # the pull back no faster than 0.2 m/s² · 0.1 s
    np.testing.assert_allclose(rule(0.2), [np.sqrt(0.016), 0.0, -0.00025, 0.0], atol=1e-15)
    assert rule(0.001)[2] == pytest.approx(-0.0001)


def test_several_height_limits_each_write_their_rows_into_one_problem(
    robot: Robot, q0: np.ndarray, state0: KinematicState
) -> None:
    """Two surface heights with different minima, gains and decelerations: each its k rows
    (by the damper rule of its own parameters), both in the problem."""
    low = float(state0.points[:, 2].min())
    limits = [
        SurfaceHeight(min_height=0.02, gain=0.3, deceleration=0.5),
        SurfaceHeight(min_height=low + 5e-5, gain=0.9, deceleration=math.inf),
    ]
    s = stepping.stepper(robot, q0, limits=limits, backend="daqp")
    for q in [q0, *configurations(robot, q0, 3, seed=21, spread=0.02)]:
        for dt in (0.001, 0.02):
            rows = [damper_rows(s, limit, q, dt, fd=q is q0) for limit in limits]
            assert rows[0].labels == rows[1].labels and rows[0].rows >= 5
            problem = s.problem()
            applies = np.isfinite(problem.h)  # a chord whose lowest point is an end: no row
            np.testing.assert_array_equal(problem.G[applies], np.vstack([r.G for r in rows]))
            np.testing.assert_array_equal(problem.h[applies], np.concatenate([r.h for r in rows]))
    s.load(q0)
    s.prepare(np.zeros(4), DT)
    rows = s.rows(limits[1])
    lowest = f"point{int(np.argmin(state0.points[:, 2])) + 1}/height"
    h = rows.h[rows.labels.index(lowest)]  # type: ignore[union-attr]
    assert h == pytest.approx(-0.9 / DT * 5e-5)  # the lowest point: 0.05 mm below


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="min_height"):
        SurfaceHeight(min_height=float("inf"))
    with pytest.raises(ParameterError, match="gain"):
        SurfaceHeight(gain=0.0)
    with pytest.raises(ParameterError, match="deceleration"):
        SurfaceHeight(deceleration=-1.0)
