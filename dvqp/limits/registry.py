"""The limits a scene file makes, in row order: one entry each.

A scene's limits are made by asking every class of :data:`SCENE_LIMITS`, in order, for its
instance (:meth:`~dvqp.limits.Limit.from_scene`: from its ``SCENE_KEYS`` of the
``[constraints]`` table, the arm and the obstacles; None when the scene does not ask for it).
Adding a limit to scene files is its own module (its class, joining the step itself, see
:mod:`dvqp.workspace.wiring`) and one entry here, or :func:`register_limit` for a limit of your
own: its keys are then valid in ``[constraints]``.
"""

from __future__ import annotations

from dvqp.errors import ParameterError
from dvqp.limits.acceleration import AccelerationLimit
from dvqp.limits.base_height import BaseHeight
from dvqp.limits.height import ProbeHeight, SurfaceHeight
from dvqp.limits.joints import JointPositionLimit, JointVelocityLimit
from dvqp.limits.limit import SHARED_KEYS, Limit
from dvqp.limits.obstacle_damper import ObstacleDamper
from dvqp.limits.self_collision import SelfCollision
from dvqp.limits.tilt import TiltLimit

SCENE_LIMITS: list[type[Limit]] = [
    JointPositionLimit,
    JointVelocityLimit,
    AccelerationLimit,
    ObstacleDamper,
    SurfaceHeight,
    ProbeHeight,
    BaseHeight,
    TiltLimit,
    SelfCollision,
]
"""Every limit a scene file makes, in the order of its rows."""


def register_limit(cls: type[Limit]) -> type[Limit]:
    """Add ``cls`` to :data:`SCENE_LIMITS` (after the others; usable as a class decorator).

    Raises
    ------
    ParameterError
        ``cls`` is not a :class:`~dvqp.limits.Limit`, or one of its ``SCENE_KEYS`` is already
        another registered limit's with another meaning.
    """
    if not (isinstance(cls, type) and issubclass(cls, Limit)):
        raise ParameterError("limit", f"{cls!r} is not a Limit class")
    if cls in SCENE_LIMITS:
        return cls
    taken = {key: other for other in SCENE_LIMITS for key in other.SCENE_KEYS}
    for key in cls.SCENE_KEYS:
        other = taken.get(key)
        if other is not None and not key.startswith(SHARED_KEYS):
            raise ParameterError(
                f"{cls.__name__}.SCENE_KEYS", f"{key!r} is already {other.__name__}'s"
            )
    SCENE_LIMITS.append(cls)
    return cls


def unregister_limit(cls: type[Limit]) -> None:
    """Remove a limit added by :func:`register_limit` (dvqp's own stay)."""
    if cls in SCENE_LIMITS[len(BUILT_IN) :]:
        SCENE_LIMITS.remove(cls)


def constraint_keys() -> tuple[str, ...]:
    """Every key the ``[constraints]`` table takes, in the limits' order."""
    return tuple(dict.fromkeys(key for cls in SCENE_LIMITS for key in cls.SCENE_KEYS))


BUILT_IN = tuple(SCENE_LIMITS)
"""dvqp's own scene limits."""
