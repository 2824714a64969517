"""Limits of the QP step, one concept per module.

A limit derives from :class:`Limit` (rows ``Constraint(G, h)`` or a ``Bounds`` box); the
distance limits derive from :class:`VelocityDamper`, which owns the damper's right-hand side
and the exact verification of its distances.
"""

from dvqp.limits.acceleration import DEFAULT_QDD_MAX, AccelerationLimit
from dvqp.limits.base_height import BaseHeight
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper, damper_value
from dvqp.limits.excess import NO_EXCESS, Excess, StartBroken, start_broken_lines
from dvqp.limits.height import ProbeHeight, SurfaceHeight, lowest_link
from dvqp.limits.joints import JointPositionLimit, JointVelocityLimit
from dvqp.limits.limit import Bounds, Constraint, Limit
from dvqp.limits.obstacle_damper import ObstacleDamper
from dvqp.limits.self_collision import SelfCollision, self_distance
from dvqp.limits.tilt import TiltLimit

__all__ = [
    "DEFAULT_DECELERATION",
    "DEFAULT_QDD_MAX",
    "NO_EXCESS",
    "AccelerationLimit",
    "BaseHeight",
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
    "StartBroken",
    "SurfaceHeight",
    "TiltLimit",
    "VelocityDamper",
    "damper_value",
    "lowest_link",
    "self_distance",
    "start_broken_lines",
]
