"""Joint position limits as velocity bounds one step ahead."""

from __future__ import annotations

import numpy as np

from dvqp.limits.limit import Bounds
from dvqp.kinematics.robot import Robot
from dvqp.kinematics.state import KinematicState


def joint_position_bounds(robot: Robot, state: KinematicState, dt: float) -> Bounds:
    """``(q_min − q)/dt ≤ Q̇ ≤ (q_max − q)/dt`` (rad/s), shape (n,) each.

    Infinite limits give infinite bounds. A joint already past a limit (which the planner never
    produces from a valid start) may not move further out: its bound is clipped at 0.
    """
    lb = np.minimum((robot.q_min - state.q) / dt, 0.0)
    ub = np.maximum((robot.q_max - state.q) / dt, 0.0)
    return Bounds(lb, ub)
