"""Velocity dampers: the base of every limit that keeps a distance above a safe value.

For a distance ``d(Q)`` (m) with safe value ``d_safe``, a damper adds the row::

    ∇d · Q̇ ≥ −γ (d − d_safe) / dt          written as   −∇d · Q̇ ≤ γ (d − d_safe) / dt

so ``d`` decays at most geometrically toward ``d_safe`` and does not cross it at first order.
A pair already closer than ``d_safe`` gets the right-hand side 0: it may not approach further
(a demanded escape speed ``γ (d_safe − d)/dt`` could exceed the velocity limits and make the
QP infeasible). A subclass implements :meth:`VelocityDamper.distances`; the base owns the
right-hand side.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Constraint


@dataclass(frozen=True)
class Distances:
    """Distances a damper keeps above their safe values, and their gradients.

    Attributes
    ----------
    value : ndarray, shape (p,)
        ``d``, m.
    gradient : ndarray, shape (p, n)
        ``∂d/∂Q``, m/rad.
    safe : float or ndarray of shape (p,)
        ``d_safe``, m.
    describe : callable, optional
        Labels of the p rows, computed only when asked.
    """

    value: NDArray[np.float64]
    gradient: NDArray[np.float64]
    safe: float | NDArray[np.float64]
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)


def damper_rhs(
    distance: NDArray[np.float64], safe: float | NDArray[np.float64], gain: float, dt: float
) -> NDArray[np.float64]:
    """``max(γ/dt · (d − d_safe), 0)``, m/s, the right-hand side of every damper row."""
    return np.maximum(gain / dt * (distance - safe), 0.0)


class VelocityDamper:
    """Base of the damper limits.

    Parameters
    ----------
    gain
        ``γ`` in (0, 1]: the fraction of the distance to the safe value that one step may
        close.
    """

    name = "damper"

    def __init__(self, gain: float = 0.5) -> None:
        if not 0.0 < float(gain) <= 1.0:
            raise ParameterError("gain", f"must be in (0, 1], got {gain!r}")
        self.gain = float(gain)

    def distances(self, state: KinematicState) -> Distances:
        """The distances this damper keeps, at ``state``."""
        raise NotImplementedError

    def compute(self, state: KinematicState, dt: float) -> Constraint:
        """``−∂d/∂Q · Q̇ ≤ max(γ/dt (d − d_safe), 0)``, one row per distance."""
        d = self.distances(state)
        return Constraint(-d.gradient, damper_rhs(d.value, d.safe, self.gain, dt), d.describe)
