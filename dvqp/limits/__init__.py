"""Limits of the QP step, one concept per module; each returns a :class:`Bounds` or a
:class:`~dvqp.limits.limit.Constraint` built from a :class:`~dvqp.kinematics.state.KinematicState`."""

from dvqp.limits.joint_position import joint_position_bounds
from dvqp.limits.joint_velocity import joint_velocity_bounds
from dvqp.limits.obstacle_damper import DamperParameters, obstacle_dampers
from dvqp.limits.surface_height import surface_height

__all__ = [
    "DamperParameters",
    "joint_position_bounds",
    "joint_velocity_bounds",
    "obstacle_dampers",
    "surface_height",
]
