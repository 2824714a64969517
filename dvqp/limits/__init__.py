"""Limits of the QP step, one concept per module.

Each limit has a ``name`` and ``compute(state, dt)`` returning a :class:`Constraint` or a
:class:`Bounds` (the :class:`Limit` protocol); the distance limits derive from
:class:`VelocityDamper`, which owns the damper's right-hand side.
"""

from dvqp.limits.damper import Distances, VelocityDamper, damper_rhs
from dvqp.limits.joint_position import JointPositionLimit
from dvqp.limits.joint_velocity import JointVelocityLimit
from dvqp.limits.limit import Bounds, Constraint, Limit
from dvqp.limits.obstacle_damper import ObstacleDamper
from dvqp.limits.surface_height import SurfaceHeight

__all__ = [
    "Bounds",
    "Constraint",
    "Distances",
    "JointPositionLimit",
    "JointVelocityLimit",
    "Limit",
    "ObstacleDamper",
    "SurfaceHeight",
    "VelocityDamper",
    "damper_rhs",
]
