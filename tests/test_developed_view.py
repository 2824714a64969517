import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from dvqp.errors import SingularConfigurationError
from dvqp.kinematics import developed_view as dv
from tests import dv_frames
from tests.common import PIPE_RADIUS, central_difference

R = PIPE_RADIUS


def frame_at(l: float, z: float, h: float, tilt: float, rng: np.random.Generator) -> np.ndarray:
    """X = [O; z axis] of a frame at DV position (l, z, h) with a random unit axis."""
    phi = l / R
    o = np.array([(R + h) * np.cos(phi), (R + h) * np.sin(phi), z])
    axis = rng.normal(size=3) + np.array([0, 0, tilt])
    return np.concatenate([o, axis / np.linalg.norm(axis)])


def wrap_lz(d: np.ndarray) -> np.ndarray:
    d = d.copy()
    d[0] = dv.wrap(d[0], R)
    d[3] = dv.wrap_angle(d[3])
    return d


@pytest.mark.parametrize("l", [0.0, 0.3, -0.5, np.pi * R - 1e-7, -np.pi * R + 1e-7, np.pi * R])
def test_coordinates_jacobian_equals_finite_differences_including_the_seam(l: float) -> None:
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = frame_at(l, rng.uniform(-1, 1), rng.uniform(0.0, 0.2), 0.3, rng)
        fd = central_difference(lambda v: dv_frames.coordinates(v[:3], v[3:], R), x, 1e-7, wrap_lz)
        an = dv_frames.coordinates_jacobian(x[:3], x[3:], R)
        np.testing.assert_allclose(an, fd, rtol=1e-6, atol=1e-6 * np.abs(an).max())


def test_coordinates_recover_the_frame_position() -> None:
    rng = np.random.default_rng(4)
    x = frame_at(0.4, 0.2, 0.08, 0.0, rng)
    l, z, h, _ = dv_frames.coordinates(x[:3], x[3:], R)
    assert l == pytest.approx(0.4) and z == pytest.approx(0.2) and h == pytest.approx(0.08)


def test_heading_is_zero_along_l_and_a_quarter_turn_along_the_pipe_axis() -> None:
    o = np.array([R + 0.1, 0.0, 0.0])
    assert dv_frames.heading(o, np.array([0.0, 1.0, 0.0])) == pytest.approx(0.0)
    assert dv_frames.heading(o, np.array([0.0, 0.0, 1.0])) == pytest.approx(np.pi / 2)


def test_point_on_pipe_axis_raises_singular_configuration() -> None:
    with pytest.raises(SingularConfigurationError, match="pipe axis"):
        dv_frames.position(np.array([[0.0, 0.0, 0.3]]), R)
    with pytest.raises(SingularConfigurationError):
        dv_frames.coordinates_jacobian(np.zeros(3), np.array([0.0, 0.0, 1.0]), R)


def test_radial_axis_gives_finite_damped_heading() -> None:
    o = np.array([R + 0.1, 0.0, 0.0])
    radial = np.array([1.0, 0.0, 0.0])
    assert np.isfinite(dv_frames.heading(o, radial))
    jac = dv_frames.coordinates_jacobian(o, radial, R)
    assert np.all(np.isfinite(jac))


@given(st.floats(-50, 50), st.floats(0.01, 2.0))
def test_wrap_lands_in_half_open_period_and_is_congruent(d: float, radius: float) -> None:
    w = float(dv.wrap(d, radius))
    period = 2 * np.pi * radius
    assert -period / 2 - 1e-12 <= w < period / 2 + 1e-12
    k = (d - w) / period
    assert abs(k - round(k)) < 1e-9


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
    np.testing.assert_allclose(dv_frames.skew(a) @ b, np.cross(a, b))
