"""The paper's arm's :class:`KinematicState`: its Jacobians against finite differences (across
the seam too), its arrays read-only and its own, its inputs checked."""

from __future__ import annotations

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from dvqp.errors import ParameterError, ShapeError
from dvqp.kinematics import developed_view as dv
from dvqp.kinematics.model import kinematics
from dvqp.workspace import StateBuffers, as_struct
from tests.common import PIPE_RADIUS, central_difference, random_configurations
from tests.kinematics import oracle

R = PIPE_RADIUS


def wrap_task(d: np.ndarray) -> np.ndarray:
    d = d.copy()
    d[..., 0] = dv.wrap(d[..., 0], R)
    if d.shape[-1] == 4:
        d[..., 3] = dv.wrap_angle(d[..., 3])
    return d


def check_jacobians(robot: Robot, q: np.ndarray) -> None:
    """Tool, guarded points (body points and probe) and frame Jacobians against central
    differences of the state's own positions and axes."""
    state = KinematicState.compute(robot, q, R)

    def fd(field: str, wrap=wrap_task) -> np.ndarray:  # type: ignore[no-untyped-def]
        f = lambda v: getattr(KinematicState.compute(robot, v, R), field)  # noqa: E731
        return central_difference(f, q, 1e-7, wrap)

    scale = np.abs(state.tool_jacobian).max()
    np.testing.assert_allclose(state.tool_jacobian, fd("tool"), rtol=1e-6, atol=1e-6 * scale)
    scale = np.abs(state.guarded_jacobians).max()
    np.testing.assert_allclose(state.guarded_jacobians, fd("guarded"), rtol=1e-6, atol=1e-6 * scale)
    jv, jw = state.frame_jacobians[:, :3], state.frame_jacobians[:, 3:]
    np.testing.assert_allclose(jv, fd("origins", None), rtol=1e-6, atol=1e-7)
    # ż = ω × z = −S(z)·J_ω·Q̇
    turn = np.array([-oracle.skew(z) @ w for z, w in zip(state.axes, jw, strict=True)])
    np.testing.assert_allclose(turn, fd("axes", None), rtol=1e-6, atol=1e-7)


def test_tool_point_and_frame_jacobians_equal_finite_differences(robot: Robot) -> None:
    for q in random_configurations(8, seed=11):
        check_jacobians(robot, q)


def test_jacobians_hold_across_the_l_seam(robot: Robot, q0: np.ndarray) -> None:
    # Turn the carriage so that the tool sits on the seam l = ±πR.
    state = KinematicState.compute(robot, q0, R)
    q = q0.copy()
    q[0] += np.pi - state.tool[0] / R
    assert abs(abs(KinematicState.compute(robot, q, R).tool[0]) - np.pi * R) < 1e-9
    check_jacobians(robot, q)
    q = q0.copy()  # body point 4 on the seam instead, the points after it across
    q[0] += np.pi - state.points[3, 0] / R
    ls = KinematicState.compute(robot, q, R).guarded[:, 0]
    assert abs(abs(ls[3]) - np.pi * R) < 1e-9
    assert (ls > 0.5 * np.pi * R).any() and (ls < -0.5 * np.pi * R).any()  # on either side
    check_jacobians(robot, q)


def test_points_are_the_first_guarded_points_the_probe_the_next_and_the_rail_point_last(
    state0: KinematicState,
) -> None:
    np.testing.assert_array_equal(state0.points, state0.guarded[:5])
    np.testing.assert_array_equal(state0.point_jacobians, state0.guarded_jacobians[:5])
    np.testing.assert_array_equal(state0.tool[:3], state0.guarded[5])
    np.testing.assert_array_equal(state0.tool_jacobian[:3], state0.guarded_jacobians[5])
    assert (state0.n, state0.k, state0.radius, state0.rail) == (13, 5, R, True)
    assert state0.guarded.shape == (7, 3)


def test_state_arrays_are_read_only(state0: KinematicState) -> None:
    for field in oracle.FIELDS:
        array = getattr(state0, field)
        with pytest.raises(ValueError, match="read-only"):
            array.flat[0] = 1.0


def test_each_state_owns_its_arrays(robot: Robot, q0: np.ndarray) -> None:
    first = KinematicState.compute(robot, q0, R)
    kept = {f: getattr(first, f).copy() for f in oracle.FIELDS}
    q0[0] += 0.5  # the caller's array is copied, not kept
    second = KinematicState.compute(robot, q0, R)
    assert not np.allclose(second.tool, first.tool)
    for field, value in kept.items():
        np.testing.assert_array_equal(getattr(first, field), value, err_msg=field)


def test_a_view_shows_whatever_its_buffers_hold_now(robot: Robot, q0: np.ndarray) -> None:
    buffers = StateBuffers.allocate(robot.n, robot.n_points, robot.has_rail)
    view = KinematicState.view(buffers, R, robot.n_points)
    model = as_struct(robot.model_arrays())
    for q in (q0, q0 + 0.1):
        buffers.q[:] = q
        assert kinematics(model, R, as_struct(buffers)) == -1
        alone = KinematicState.compute(robot, q, R)
        for field in oracle.FIELDS:
            np.testing.assert_array_equal(getattr(view, field), getattr(alone, field))
    with pytest.raises(ValueError, match="read-only"):
        view.tool[0] = 0.0


def test_start_configuration_lies_at_the_orbital_level(state0: KinematicState) -> None:
    np.testing.assert_allclose(state0.points[:, 2], 0.08, atol=2e-3)
    assert abs(state0.tool[3]) < 1e-3


def test_wrong_configuration_size_raises_shape_error(robot: Robot) -> None:
    with pytest.raises(ShapeError, match=r"q: expected shape \(13,\), got \(12,\)"):
        KinematicState.compute(robot, np.zeros(12), R)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_configuration_that_is_not_finite_is_refused(
    robot: Robot, q0: np.ndarray, bad: float
) -> None:
    q0[3] = bad
    with pytest.raises(ParameterError, match="q: must be finite"):
        KinematicState.compute(robot, q0, R)


@pytest.mark.parametrize("radius", [np.nan, np.inf, 0.0, -0.1])
def test_a_bad_pipe_radius_is_refused(robot: Robot, q0: np.ndarray, radius: float) -> None:
    with pytest.raises(ParameterError, match="radius"):
        KinematicState.compute(robot, q0, radius)
