"""Velocity dampers: the base of every limit that keeps a distance above a safe value.

For a distance ``d(Q)`` (m) with safe value ``d_safe`` and room ``r = d − d_safe``, a damper
adds the row ``∇d · Q̇ ≥ −rhs``, written ``−∇d · Q̇ ≤ rhs``, with::

    rhs = min(γ r / dt, sqrt(2 a r))     r ≥ 0      decay toward d_safe, braking in time
    rhs = max(γ r / dt, −a dt)           −δ ≤ r < 0  a drift below d_safe is pulled back
    rhs = 0                              r < −δ     a part that starts inside: no worse

Above ``d_safe``, ``d`` decays at most geometrically toward it, no faster than the braking
speed for a deceleration ``a``, and does not cross it at first order. A second-order drift of
at most ``δ`` (the damper's verification tolerance, 0.1 mm) below it is pulled back, so it
settles at about ``|ε|/γ`` instead of adding up step after step; the return is asked no faster
than one step's acceleration. A part deeper inside (it started there) may not get worse, and
no escape it might not be able to make is demanded; the objective pushes body points out of
obstacles and toward the orbital level. A subclass implements :meth:`VelocityDamper.distances`;
the base owns the right-hand side.

The compiled step (:mod:`dvqp.compiled`) uses the scalar twin
:func:`~dvqp.limits.damper_kernels.damper_value` of :func:`damper_rhs`, the same operations in
the same order (equal bit for bit); a built-in damper's :meth:`~VelocityDamper.kernel` writes
its rows with it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.excess import NO_EXCESS, Excess
from dvqp.limits.limit import Constraint

DEFAULT_DECELERATION = 1.0
"""m/s²: the default braking of a damper's approach, within what the arm's joints, limited to
10 rad/s², can give at its points (lever arms up to about 0.5 m)."""


@dataclass(frozen=True)
class Distances:
    """Distances a damper keeps above their safe values, and their gradients.

    Attributes
    ----------
    value : ndarray, shape (p,)
        ``d``, m.
    gradient : ndarray, shape (p, n), or None
        ``∂d/∂Q``, m/rad (None where only the values are wanted, for verification).
    safe : float or ndarray of shape (p,)
        ``d_safe``, m.
    describe : callable, optional
        Labels of the p rows, computed only when asked.
    """

    value: NDArray[np.float64]
    gradient: NDArray[np.float64] | None
    safe: float | NDArray[np.float64]
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)


def damper_rhs(
    distance: NDArray[np.float64],
    safe: float | NDArray[np.float64],
    gain: float,
    dt: float,
    depth: float,
    deceleration: float = math.inf,
) -> NDArray[np.float64]:
    """``γ/dt · (d − d_safe)``, capped above ``d_safe`` by the braking speed
    ``sqrt(2 a (d − d_safe))``; below it, a drift of at most ``δ`` is pulled back no faster
    than one step's acceleration ``a·dt``, and deeper (a start inside the margin) the distance
    may only not shrink (0): m/s, the right-hand side of every damper row."""
    room = distance - safe
    # a drift of at most δ below the safe value is pulled back; deeper (a start inside the
    # margin) the distance may only not shrink: an escape it may not be able to make is not
    # demanded
    rhs = np.where(room < -depth, 0.0, gain / dt * room)
    if math.isinf(deceleration):
        return rhs
    # above: brake in time; below: ask for no faster a return than one step's acceleration
    return np.clip(rhs, -deceleration * dt, np.sqrt(2.0 * deceleration * np.maximum(room, 0.0)))


class VelocityDamper:
    """Base of the damper limits.

    Parameters
    ----------
    gain
        ``γ`` in (0, 1]: the fraction of the distance to the safe value that one step may
        close.
    deceleration
        ``a`` (m/s², or the distance's unit per s²), > 0: the approach speed is at most
        ``sqrt(2 a (d − d_safe))``, so a part slows down in time for joints whose accelerations
        are limited; ``inf`` removes the cap.
    """

    name = "damper"
    quantity = "distance"
    """What the distance is, for reports (``"clearance"``, ``"height"``)."""
    tolerance = 1e-4
    """m: how far below ``min(d_safe, d at the start)`` an integrated step may end."""

    def __init__(self, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION) -> None:
        if not 0.0 < float(gain) <= 1.0:
            raise ParameterError("gain", f"must be in (0, 1], got {gain!r}")
        if not float(deceleration) > 0.0:
            raise ParameterError("deceleration", f"must be > 0, got {deceleration!r}")
        self.gain = float(gain)
        self.deceleration = float(deceleration)

    def distances(self, state: KinematicState) -> Distances:
        """The distances this damper keeps at ``state``, with their gradients (the rows)."""
        raise NotImplementedError

    def all_distances(self, state: KinematicState) -> Distances:
        """Every distance the damper guards, in a fixed order, gradients not needed.

        The default is :meth:`distances`; a damper that adds rows only for nearby pairs
        returns all pairs here, so a pair that jumps from far to inside its margin in one
        step is caught.
        """
        return self.distances(state)

    def params(self, safe: float) -> tuple[float, float, float, float]:
        """``(d_safe, γ, δ, a)``: the parameter tuple of the compiled damper kernels
        (:mod:`dvqp.limits.damper_kernels`), with ``δ`` the tolerance."""
        return (float(safe), self.gain, float(self.tolerance), self.deceleration)

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """The compiled rows (see :class:`~dvqp.limits.limit.Limit`); a subclass without one
        raises NotImplementedError, so the run takes the reference path."""
        raise NotImplementedError(f"{type(self).__name__} has no compiled kernel")

    def verifier(self, plan: StepPlan) -> Kernel | None:
        """The compiled verification values (see :mod:`dvqp.limits.excess`); a subclass without
        one raises NotImplementedError, so the run takes the reference path."""
        raise NotImplementedError(f"{type(self).__name__} has no compiled verifier")

    def compute(self, state: KinematicState, dt: float) -> Constraint:
        """``−∂d/∂Q · Q̇ ≤ γ/dt · max(d − d_safe, −δ)``, one row per distance."""
        d = self.distances(state)
        if d.gradient is None:
            raise ValueError(f"{type(self).__name__}.distances must return gradients")
        rhs = damper_rhs(d.value, d.safe, self.gain, dt, self.tolerance, self.deceleration)
        return Constraint(-d.gradient, rhs, d.describe)

    def excess(self, start: KinematicState, state: KinematicState) -> Excess:
        """How far ``state`` is below ``min(d_safe, d(start))``, m, for the worst distance."""
        floor = start.cache.get((self, "floor"))
        if floor is None:  # the start's floors are the same at every step of a run
            b = self.all_distances(start)
            floor = np.minimum(b.safe, b.value)
            start.cache[(self, "floor")] = floor
        a = self.all_distances(state)
        if a.value.shape[0] == 0:
            return NO_EXCESS
        over = floor - a.value
        i = int(np.argmax(over))
        label = a.describe()[i] if a.describe is not None and over[i] > 0.0 else ""
        return Excess(
            float(over[i]), self.tolerance, label, self.quantity, "m",
            float(a.value[i]), float(floor[i]),
        )  # fmt: skip
