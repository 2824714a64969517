"""JOG commands: segments sampled every dt, ramped so the commanded velocity is continuous."""

import numpy as np
import pytest

from dvqp import JogSegment, jog_commands
from dvqp.errors import ParameterError

SEGMENTS = [
    JogSegment(0.5, np.array([0.06, 0.0, 0.0, 0.0])),
    JogSegment(0.3, np.array([0.0, -0.04, 0.0, 0.5])),
]


def test_without_a_ramp_the_segments_are_held_as_given() -> None:
    cmd = jog_commands(SEGMENTS, 0.01)
    assert cmd.shape == (80, 4)
    np.testing.assert_array_equal(cmd[:50], np.tile(SEGMENTS[0].velocity, (50, 1)))


def test_a_ramp_makes_every_change_linear_and_keeps_the_displacement() -> None:
    dt, ramp = 0.01, 0.1
    held, ramped = jog_commands(SEGMENTS, dt), jog_commands(SEGMENTS, dt, ramp)
    window = round(ramp / dt)
    assert ramped.shape == (80 + window - 1, 4)
    np.testing.assert_allclose(ramped.sum(axis=0) * dt, held.sum(axis=0) * dt, atol=1e-15)
    jumps = np.abs(np.diff(np.vstack([np.zeros(4), ramped, np.zeros(4)]), axis=0))
    biggest = np.abs(np.diff(np.vstack([np.zeros(4), held, np.zeros(4)]), axis=0)).max(axis=0)
    assert np.all(jumps <= biggest / window + 1e-15)  # from rest, between segments, to rest


def test_bad_ramps_are_refused() -> None:
    with pytest.raises(ParameterError, match="ramp"):
        jog_commands(SEGMENTS, 0.01, -0.1)
