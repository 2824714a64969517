"""The developed-view map of one frame, ``F(X) = [l, z, h, α]`` with ``X = [O; z]``, as the
compiled kinematics computes it: against finite differences (across the seam ``l = ±πR``),
hand-worked cases and the NumPy formulas; and the wrapping helpers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from dvqp import KinematicState
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics import developed_view as dv
from tests.common import PIPE_RADIUS, central_difference
from tests.kinematics import oracle

R = PIPE_RADIUS
FREE = oracle.free_frame_robot()


def tool_state(origin: np.ndarray, axis: np.ndarray) -> KinematicState:
    """The kinematics with the tool frame at ``origin`` (m), its z axis along ``axis``."""
    return KinematicState.compute(FREE, oracle.free_frame_q(origin, axis), R)


def random_frame(l: float, rng: np.random.Generator) -> np.ndarray:
    """The free frame's q at DV position (l, random z, random h ≥ 0), with a random axis."""
    o = oracle.on_surface(l, rng.uniform(-1, 1), rng.uniform(0.0, 0.2), R)
    return oracle.free_frame_q(o, rng.normal(size=3) + np.array([0.0, 0.0, 0.3]))


def wrap_lz(d: np.ndarray) -> np.ndarray:
    d = d.copy()
    d[..., 0] = dv.wrap(d[..., 0], R)
    if d.shape[-1] == 4:
        d[..., 3] = dv.wrap_angle(d[..., 3])
    return d


@pytest.mark.parametrize("l", [0.0, 0.3, -0.5, np.pi * R - 1e-7, -np.pi * R + 1e-7, np.pi * R])
def test_the_tool_and_point_rows_equal_finite_differences_including_the_seam(l: float) -> None:
    """Joints PX, PY, PZ move the origin, RZ·RY turn the axis anywhere: the rows ∂F/∂q hold
    every partial of F(X)."""
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = random_frame(l, rng)
        state = KinematicState.compute(FREE, q, R)
        fd = central_difference(lambda v: KinematicState.compute(FREE, v, R).tool, q, 1e-7, wrap_lz)
        scale = np.abs(state.tool_jacobian).max()
        np.testing.assert_allclose(state.tool_jacobian, fd, rtol=1e-6, atol=1e-6 * scale)
        fd = central_difference(
            lambda v: KinematicState.compute(FREE, v, R).guarded, q, 1e-7, wrap_lz
        )
        np.testing.assert_allclose(state.guarded_jacobians, fd, rtol=1e-6, atol=1e-7)


@pytest.mark.parametrize("l", [0.0, -0.5, np.pi * R])
def test_the_map_and_its_rows_equal_the_formulas(l: float) -> None:
    rng = np.random.default_rng(9)
    for _ in range(10):
        q = random_frame(l, rng)
        state = KinematicState.compute(FREE, q, R)
        for field, want in oracle.reference(FREE, q, R).items():
            np.testing.assert_allclose(
                getattr(state, field), want, rtol=0, atol=1e-12, err_msg=field
            )


def test_the_coordinates_recover_the_frame_position() -> None:
    o = oracle.on_surface(0.4, 0.2, 0.08, R)
    l, z, h, _ = tool_state(o, np.array([0.3, -0.2, 0.9])).tool
    assert l == pytest.approx(0.4, abs=1e-12) and z == pytest.approx(0.2, abs=1e-12)
    assert h == pytest.approx(0.08, abs=1e-12)


def test_the_seam_is_at_l_equal_to_plus_or_minus_pi_r() -> None:
    above = tool_state(oracle.on_surface(np.pi * R - 1e-6, 0.0, 0.05, R), np.array([0, 0, 1.0]))
    below = tool_state(oracle.on_surface(np.pi * R + 1e-6, 0.0, 0.05, R), np.array([0, 0, 1.0]))
    assert above.tool[0] == pytest.approx(np.pi * R - 1e-6, abs=1e-12)
    assert below.tool[0] == pytest.approx(-np.pi * R + 1e-6, abs=1e-12)


@pytest.mark.parametrize("phi", [0.0, 1.0, -2.5])
def test_heading_is_zero_along_l_a_quarter_turn_along_the_pipe_axis_and_half_a_turn_back(
    phi: float,
) -> None:
    o = oracle.on_surface(R * phi, 0.1, 0.1, R)
    along_l = np.array([-math.sin(phi), math.cos(phi), 0.0])
    assert tool_state(o, along_l).tool[3] == pytest.approx(0.0, abs=1e-12)
    assert tool_state(o, np.array([0.0, 0.0, 1.0])).tool[3] == pytest.approx(np.pi / 2)
    assert abs(tool_state(o, -along_l).tool[3]) == pytest.approx(np.pi)
    diagonal = along_l + np.array([0.0, 0.0, 1.0])
    assert tool_state(o, diagonal).tool[3] == pytest.approx(np.pi / 4)


def test_a_tool_on_the_pipe_axis_raises_singular_configuration() -> None:
    with pytest.raises(SingularConfigurationError, match=r"frame 'tool' lies on the pipe axis"):
        tool_state(np.array([0.0, 0.0, 0.3]), np.array([0.0, 0.0, 1.0]))
    with pytest.raises(SingularConfigurationError, match="pipe axis"):
        tool_state(np.array([1e-10, -1e-10, 0.3]), np.array([1.0, 0.0, 0.0]))


@pytest.mark.parametrize("axis", [[1.0, 0.0, 0.0], [1.0, 1e-5, 0.0], [1.0, 0.0, -1e-5]])
def test_a_radial_axis_gives_a_finite_heading_and_a_bounded_row(axis: list[float]) -> None:
    o = np.array([R + 0.1, 0.0, 0.0])
    state = tool_state(o, np.array(axis))
    assert np.isfinite(state.tool[3])
    assert np.all(np.isfinite(state.tool_jacobian))
    # |∂α/∂X| ≤ 1/sqrt(floor) per unit of frame motion: bounded however close to radial
    bound = np.abs(state.frame_jacobians[-1]).sum(axis=0) / math.sqrt(oracle.HEADING_FLOOR)
    assert (np.abs(state.tool_jacobian[3]) <= bound).all()
    want = oracle.reference(FREE, state.q, R)["tool_jacobian"]
    np.testing.assert_allclose(state.tool_jacobian, want, rtol=1e-12, atol=1e-12)


def test_the_heading_row_is_exact_a_few_milliradians_from_radial() -> None:
    """The floor on c² + s² (1e-6) does not bite 5 mrad away from radial: the row is exact."""
    o = np.array([R + 0.1, 0.0, 0.0])
    q = oracle.free_frame_q(o, [1.0, math.tan(5e-3), 0.0])
    state = KinematicState.compute(FREE, q, R)
    fd = central_difference(lambda v: KinematicState.compute(FREE, v, R).tool, q, 1e-8, wrap_lz)
    np.testing.assert_allclose(state.tool_jacobian[3], fd[3], rtol=1e-5, atol=1e-9)
    assert np.abs(state.tool_jacobian[3]).max() > 100.0  # the heading turns fast here


@given(st.floats(-50, 50), st.floats(0.01, 2.0))
def test_wrap_lands_in_half_open_period_and_is_congruent(d: float, radius: float) -> None:
    w = float(dv.wrap(d, radius))
    period = 2 * np.pi * radius
    assert -period / 2 - 1e-12 <= w < period / 2 + 1e-12
    k = (d - w) / period
    assert abs(k - round(k)) < 1e-9


@given(st.floats(-50, 50))
def test_wrap_angle_and_wrap_period_agree_with_wrap(d: float) -> None:
    assert float(dv.wrap_angle(d)) == float(dv.wrap(d, 1.0))
    assert float(dv.wrap_period(d, 0.3)) == pytest.approx(float(dv.wrap(d, 0.3 / (2 * np.pi))))


@given(st.lists(st.floats(-0.05, 0.05), min_size=2, max_size=50), st.floats(-3, 3))
def test_unwrap_recovers_a_continuous_path_crossing_the_seam(
    steps: list[float], start: float
) -> None:
    true = start + np.cumsum(steps)
    wrapped = dv.wrap(true, R)
    np.testing.assert_allclose(
        dv.unwrap(wrapped, 2 * np.pi * R), true - (true[0] - wrapped[0]), atol=1e-9
    )


def test_skew_is_the_cross_product() -> None:
    a, b = np.array([0.1, -0.4, 0.7]), np.array([0.3, 0.2, -0.5])
    np.testing.assert_allclose(oracle.skew(a) @ b, np.cross(a, b))
