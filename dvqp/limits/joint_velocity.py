"""Joint velocity limits."""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.kinematics.robot import Robot
from dvqp.limits.limit import Limit


class JointVelocityLimit(Limit):
    """``−q̇_max ≤ Q̇ ≤ q̇_max`` (rad/s), from the robot's ``qd_max``, shape (n,) (compiled:
    :func:`velocity_bounds`).

    A bound of the QP held exactly by every accepted solution (the solution check recomputes
    it), so it needs no exact verification of the integrated motion.
    """

    name = "joint_velocity"

    def __init__(self, robot: Robot) -> None:
        self.qd_max = robot.qd_max


@njit(cache=True)
def velocity_bounds(qd_max: NDArray[np.float64], lb: NDArray[np.float64],
                    ub: NDArray[np.float64]) -> None:  # fmt: skip
    """``−q̇_max ≤ Q̇ ≤ q̇_max``, intersected into ``lb``, ``ub`` in place."""
    for i in range(qd_max.shape[0]):
        lb[i] = max(lb[i], -qd_max[i])
        ub[i] = min(ub[i], qd_max[i])
