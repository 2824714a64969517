"""Joint position limits as velocity bounds one step ahead."""

from __future__ import annotations

import numpy as np

from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Bounds


class JointPositionLimit:
    """``(q_min − q)/dt ≤ Q̇ ≤ (q_max − q)/dt`` (rad/s), from the robot's limits.

    Infinite limits give infinite bounds. A joint already past a limit (which the planner never
    produces from a valid start) may not move further out: its bound is clipped at 0.

    Parameters
    ----------
    robot
        Its ``q_min`` and ``q_max`` (rad), shape (n,).
    """

    name = "joint_position"

    def __init__(self, robot: Robot) -> None:
        self.q_min = robot.q_min
        self.q_max = robot.q_max

    def compute(self, state: KinematicState, dt: float) -> Bounds:
        """The box at ``state.q``, shape (n,) each."""
        lb = np.minimum((self.q_min - state.q) / dt, 0.0)
        ub = np.maximum((self.q_max - state.q) / dt, 0.0)
        return Bounds(lb, ub)
