import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ShapeError
from dvqp.kinematics import developed_view as dv
from tests.common import PIPE_RADIUS, central_difference, random_configurations

R = PIPE_RADIUS


def wrap_task(d: np.ndarray) -> np.ndarray:
    d = d.copy()
    d[..., 0] = dv.wrap(d[..., 0], R)
    if d.shape[-1] == 4:
        d[..., 3] = dv.wrap_angle(d[..., 3])
    return d


def check_jacobians(robot: Robot, q: np.ndarray) -> None:
    state = KinematicState.compute(robot, q, R)
    fd_tool = central_difference(
        lambda v: KinematicState.compute(robot, v, R).tool, q, 1e-7, wrap_task
    )
    scale = np.abs(state.tool_jacobian).max()
    np.testing.assert_allclose(state.tool_jacobian, fd_tool, rtol=1e-6, atol=1e-6 * scale)
    fd_pts = central_difference(
        lambda v: KinematicState.compute(robot, v, R).points, q, 1e-7, wrap_task
    )
    np.testing.assert_allclose(
        state.point_jacobians,
        fd_pts.reshape(state.point_jacobians.shape),
        rtol=1e-6,
        atol=1e-6 * np.abs(state.point_jacobians).max(),
    )


def test_tool_and_point_jacobians_equal_finite_differences(robot: Robot) -> None:
    for q in random_configurations(8, seed=11):
        check_jacobians(robot, q)


def test_jacobians_hold_across_the_l_seam(robot: Robot, q0: np.ndarray) -> None:
    # Turn the carriage so that the tool sits on the seam l = ±πR.
    state = KinematicState.compute(robot, q0, R)
    q = q0.copy()
    q[0] += np.pi - state.tool[0] / R
    assert abs(abs(KinematicState.compute(robot, q, R).tool[0]) - np.pi * R) < 1e-9
    check_jacobians(robot, q)
    q[0] -= 0.15  # a body point on the seam instead
    check_jacobians(robot, q)


def test_state_arrays_are_read_only(state0: KinematicState) -> None:
    with pytest.raises(ValueError):
        state0.tool[0] = 1.0
    with pytest.raises(ValueError):
        state0.point_jacobians[0, 0, 0] = 1.0


def test_start_configuration_lies_at_the_orbital_level(state0: KinematicState) -> None:
    np.testing.assert_allclose(state0.points[:, 2], 0.08, atol=2e-3)
    assert abs(state0.tool[3]) < 1e-3


def test_wrong_configuration_size_raises_shape_error(robot: Robot) -> None:
    with pytest.raises(ShapeError, match=r"q: expected shape \(13,\), got \(12,\)"):
        KinematicState.compute(robot, np.zeros(12), R)


def test_nan_configuration_is_refused(robot: Robot, q0: np.ndarray) -> None:
    q0[3] = np.nan
    with pytest.raises(ValueError, match="finite"):
        KinematicState.compute(robot, q0, R)


@pytest.mark.parametrize("radius", [np.nan, np.inf, 0.0, -0.1])
def test_a_bad_pipe_radius_is_refused(robot: Robot, q0: np.ndarray, radius: float) -> None:
    with pytest.raises(ValueError, match="radius"):
        KinematicState.compute(robot, q0, radius)
