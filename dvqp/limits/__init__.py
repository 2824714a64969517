"""Limits of the QP step, one concept per module.

Each limit has a ``name`` and ``compute(state, dt)`` returning a :class:`Constraint` or a
:class:`Bounds` (the :class:`Limit` protocol); the distance limits derive from
:class:`VelocityDamper`, which owns the damper's right-hand side.
"""

from dvqp.limits.acceleration import DEFAULT_QDD_MAX, AccelerationLimit
from dvqp.limits.damper import Distances, VelocityDamper, damper_rhs
from dvqp.limits.excess import NO_EXCESS, Excess, VerifiedLimit, worst_excess
from dvqp.limits.joint_position import JointPositionLimit
from dvqp.limits.joint_velocity import JointVelocityLimit
from dvqp.limits.limit import Bounds, Constraint, Limit
from dvqp.limits.obstacle_damper import ObstacleDamper
from dvqp.limits.probe_height import ProbeHeight
from dvqp.limits.self_collision import SelfCollision, self_distance
from dvqp.limits.surface_height import SurfaceHeight
from dvqp.limits.tilt import TiltLimit, tilt, tilt_cosine, tilt_sine

__all__ = [
    "DEFAULT_QDD_MAX",
    "NO_EXCESS",
    "AccelerationLimit",
    "Bounds",
    "Constraint",
    "Distances",
    "Excess",
    "JointPositionLimit",
    "JointVelocityLimit",
    "Limit",
    "ObstacleDamper",
    "ProbeHeight",
    "SelfCollision",
    "SurfaceHeight",
    "TiltLimit",
    "VelocityDamper",
    "VerifiedLimit",
    "damper_rhs",
    "self_distance",
    "tilt",
    "tilt_cosine",
    "tilt_sine",
    "worst_excess",
]
