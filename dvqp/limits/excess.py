"""Exact verification of a step: how far the integrated motion went past each limit.

The QP holds the limits linearised one step ahead; the motion that is integrated may still
go past them (second-order terms, large steps). After each step the resolution loop evaluates
every limit that can verify itself (the :class:`VerifiedLimit` protocol) at the configuration
actually reached, without linearisation, and keeps the worst :class:`Excess`.

A limit is kept if its quantity stays at or above ``min(bound, value at the start of the
run)``: a part that starts closer than its margin may stay there but may not get worse, and
small excesses cannot add up from step to step.

Compiled verification. A verified limit also provides ``verifier(plan)``: a
:class:`~dvqp.compiled.plan.Kernel` that writes the limit's exact quantities at
``plan.state`` into ``slot = plan.verified(limit, count, safe, tolerance)`` (None when there is
nothing to check, e.g. a tilt limit with ``min_tilt = 0`` or a damper without obstacles;
NotImplementedError when it cannot be compiled). With the values at the run's start,
``floor = minimum(safe, values_at_start)`` (fixed for the run), the limit's
:meth:`VerifiedLimit.excess` value at a state is ``max(floor − values)`` over its slice, its
tolerance is ``tolerance``, and :func:`worst_excess` is the entry of largest
``(floor − value) / tolerance`` over all slices. The values are:

- a damper: its distances in the order of ``all_distances`` (m; safe ``d_safe``, tolerance
  0.1 mm): an obstacle damper every point's clearance (J × (k+1), obstacle-major), then every
  link's (J × k); the surface height the k body points' heights; the probe height the probe's;
  self-collision every non-adjacent pair's distance;
- joint positions ``[q_max − q, q − q_min]`` (2n, rad; safe 0, tolerance 1e-6 rad; ``inf`` on
  an unlimited side, so ``floor − value = −inf`` there, never NaN);
- the tilt ``asin(min(sin θ, 1))`` (one value, rad; safe ``asin(min(sin θ_min, 1))``,
  tolerance 1e-3 rad).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Excess:
    """How far a motion went past one limit, in the limit's unit.

    Attributes
    ----------
    value : float
        Amount past the bound (> 0 broken, <= 0 kept with that much room), m or rad.
    tolerance : float
        The limit's verification tolerance, same unit: the step is accepted up to it.
    label : str
        What broke it, e.g. ``"probe/obstacle3"``, ``"point2/height"``, ``"joint4"``.
    quantity : str
        ``"clearance"``, ``"height"``, ``"tilt"``, ``"joint position"``, ...
    unit : str
        ``"m"``, ``"rad"`` or ``"rad/s"``.
    actual, bound : float
        The value reached and the bound it had to keep.
    """

    value: float
    tolerance: float
    label: str = ""
    quantity: str = ""
    unit: str = ""
    actual: float = 0.0
    bound: float = 0.0

    @property
    def broken(self) -> bool:
        """Past the bound by more than the tolerance (a NaN value counts as past it)."""
        return not self.value <= self.tolerance

    @property
    def ratio(self) -> float:
        """``value / tolerance``: how the worst of several limits is chosen."""
        return self.value / self.tolerance

    def describe(self) -> str:
        """One line, e.g. ``"probe/obstacle3 clearance 0.0061 m < 0.0099 m (by 3.8 mm)"``."""
        if math.isinf(self.value):
            return f"{self.label} ({self.quantity})"
        if self.unit == "m":
            by = f"{self.value * 1e3:.3g} mm"
        else:
            by = f"{self.value:.3g} {self.unit}"
        below = "<" if self.quantity not in ("joint position", "joint velocity") else "past"
        return (
            f"{self.label} {self.quantity} {self.actual:.4g} {self.unit} {below} "
            f"{self.bound:.4g} {self.unit} (by {by})"
        )


NO_EXCESS = Excess(value=-float("inf"), tolerance=1.0)
"""What a limit with nothing to check reports."""


@runtime_checkable
class VerifiedLimit(Protocol):
    """A limit that can check a motion exactly (all built-in limits can)."""

    def excess(self, start: KinematicState, state: KinematicState) -> Excess:
        """The worst excess at ``state`` of a run that started at ``start``."""
        ...


def worst_excess(limits: Iterable[object], start: KinematicState, state: KinematicState) -> Excess:
    """The worst :class:`Excess` (largest ``value / tolerance``) of every verifiable limit.

    Limits without an ``excess`` method (a user's limit may have none) are not checked.
    """
    worst = NO_EXCESS
    for limit in limits:
        check = getattr(limit, "excess", None)
        if check is None:
            continue
        found = check(start, state)
        if found.ratio > worst.ratio or math.isnan(found.ratio):  # a NaN is the worst
            worst = found
            if math.isnan(found.ratio):
                break
    return worst
