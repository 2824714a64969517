"""Developed-view (DV) coordinates around a pipe: the map, its constants and l's period.

The pipe axis is the base z axis; ``R`` is the pipe radius (m). For a point ``O`` (m) with a
unit axis ``z``, ``ρ = sqrt(Ox² + Oy²)``::

    l = R · atan2(Oy, Ox)            arc length along the circumference, m, in (−πR, πR]
    z = Oz                           position along the pipe axis, m
    h = ρ − R                        height above the pipe surface, m
    α = atan2(zz, (Ox·zy − Oy·zx)/ρ) heading of z on the surface, rad, from l toward z

The map and its Jacobian are computed by the compiled kinematics
(:func:`dvqp.kinematics.model.kinematics`). A point on the pipe axis is singular
(:class:`~dvqp.errors.SingularConfigurationError`); an undefined heading (the axis radial)
gives a Jacobian row bounded by :data:`HEADING_FLOOR`.
"""

from __future__ import annotations

import math

import numpy as np
from numba.extending import register_jitable
from numpy.typing import ArrayLike, NDArray

RHO_MIN = 1e-9
"""Distance from the pipe axis (m) below which a point is singular."""

HEADING_FLOOR = 1e-6
"""Floor on ``c² + s²`` in the heading Jacobian (dimensionless): exact when the tool axis is
more than about 1 mrad away from radial, bounded and finite closer to it."""


@register_jitable
def wrap_period(difference, period):  # type: ignore[no-untyped-def]
    """A difference of values of period ``period`` wrapped into ``[−period/2, period/2)`` (to
    a rounding at its ends): a float or an array (from Python), a float (from compiled code).
    A difference inside it (not within a rounding of its ends) comes back unchanged, bit for
    bit. The nearest whole number of periods is taken off with ``floor``: compiled, about
    1.4 ns a call, where Python's float ``%`` (``fmod`` and a floor division) took about 10 ns
    (a loop over 10⁵ floats); the broad phase and the circles call it hundreds of times a
    step."""
    return difference - period * np.floor(difference / period + 0.5)


def wrap(dl: ArrayLike, radius: float) -> NDArray[np.float64]:
    """Wrap arc-length differences into ``[−πR, πR)``, m, same shape as ``dl``."""
    return wrap_period(np.asarray(dl, dtype=np.float64), 2.0 * math.pi * radius)  # type: ignore[no-any-return]


def wrap_angle(da: ArrayLike) -> NDArray[np.float64]:
    """Wrap angle differences into ``[−π, π)``, rad."""
    return wrap(da, 1.0)  # a circle of radius 1 has period 2π


def unwrap(values: ArrayLike, period: float, axis: int = 0) -> NDArray[np.float64]:
    """Unwrap a sequence of wrapped values (arc length or angle) along ``axis``.

    Each increment is wrapped into ``[−period/2, period/2)`` and accumulated from the first
    value, so a path that crosses the seam ``l = ±πR`` becomes continuous.
    """
    v = np.asarray(values, dtype=np.float64)
    d = wrap_period(np.diff(v, axis=axis), period)
    first = np.take(v, [0], axis=axis)
    return np.concatenate([first, first + np.cumsum(d, axis=axis)], axis=axis)
