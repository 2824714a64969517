"""Shared fixtures: the paper's arm built in code, its start configuration and a pipe."""

from __future__ import annotations

import numpy as np
import pytest

from dvqp import KinematicState, Robot
from tests.common import LINK_LENGTHS, PIPE_RADIUS, Q0


@pytest.fixture(scope="session")
def robot() -> Robot:
    return Robot.ndt13(LINK_LENGTHS)


@pytest.fixture
def q0() -> np.ndarray:
    return np.array(Q0)


@pytest.fixture
def state0(robot: Robot, q0: np.ndarray) -> KinematicState:
    return KinematicState.compute(robot, q0, PIPE_RADIUS)
