"""Joint velocity limits."""

from __future__ import annotations

from dvqp.limits.limit import Bounds
from dvqp.kinematics.robot import Robot


def joint_velocity_bounds(robot: Robot) -> Bounds:
    """``−q̇_max ≤ Q̇ ≤ q̇_max`` (rad/s), shape (n,) each."""
    return Bounds(-robot.qd_max, robot.qd_max.copy())
