"""Surface height: one damper row per body point, minus the height gradient."""

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError
from dvqp.limits import SurfaceHeight, damper_rhs
from tests.common import PIPE_RADIUS, central_difference
from tests.limit_fixtures import DT


def test_height_rows_are_minus_the_height_gradient(robot: Robot, q0: np.ndarray) -> None:
    state = KinematicState.compute(robot, q0, PIPE_RADIUS)
    rows = SurfaceHeight(min_height=0.02, gain=0.5).compute(state, DT)
    fd = central_difference(
        lambda v: KinematicState.compute(robot, v, PIPE_RADIUS).points[:, 2], q0, 1e-7
    )
    np.testing.assert_allclose(-rows.G, fd, rtol=1e-6, atol=1e-8)
    room = state.points[:, 2] - 0.02
    np.testing.assert_allclose(rows.h, np.minimum(0.5 / DT * room, np.sqrt(2.0 * room)))
    assert rows.labels == tuple(f"point{i}/height" for i in range(1, 6))


def test_a_point_well_below_the_minimum_may_only_not_descend(state0: KinematicState) -> None:
    above = float(state0.points[:, 2].max()) + 0.01
    rows = SurfaceHeight(min_height=above, gain=0.5).compute(state0, DT)
    np.testing.assert_array_equal(rows.h, 0.0)


def test_damper_rhs_decays_brakes_pulls_small_drifts_back_and_holds_deep_starts() -> None:
    d = np.array([0.05, 0.01, 0.00995, -0.02])
    # 4 cm above: decay; at the margin: 0; 0.05 mm below: pulled back; 3 cm below: held
    np.testing.assert_allclose(
        damper_rhs(d, 0.01, 0.5, 0.1, 1e-4), [0.2, 0.0, -0.00025, 0.0], atol=1e-15
    )
    # with a deceleration of 0.2 m/s², 4 cm away: at most sqrt(2·0.2·0.04) = 0.126 m/s;
    # the pull back no faster than 0.2 m/s² · 0.1 s
    capped = damper_rhs(d, 0.01, 0.5, 0.1, 1e-4, deceleration=0.2)
    np.testing.assert_allclose(capped, [np.sqrt(0.016), 0.0, -0.00025, 0.0], atol=1e-15)
    slow = damper_rhs(d, 0.01, 0.5, 0.1, 1e-4, deceleration=0.001)
    assert slow[2] == pytest.approx(-0.0001)


def test_constructor_validates_its_parameters() -> None:
    with pytest.raises(ParameterError, match="min_height"):
        SurfaceHeight(min_height=float("inf"))
    with pytest.raises(ParameterError, match="gain"):
        SurfaceHeight(gain=0.0)
