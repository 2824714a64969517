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
than one step's acceleration. A part deeper inside (it started there) may not get worse.

A damper only measures its distances (``d``, ``∂d/∂Q``, whether the row applies); the rows and
their exact verification are the same compiled code for every damper (:func:`damper_rows`,
:func:`damper_values`). dvqp's dampers measure in compiled kernels of their own modules; one of
yours derives from :class:`VelocityDamper` and implements :meth:`VelocityDamper.distances` in
NumPy, or brings a kernel (:meth:`VelocityDamper.kernel`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.limit import Limit
from dvqp.workspace import Kernel, PartNames, StepPlan
from dvqp.workspace.wiring import StepWiring
from solvers.jit import njit

Array = NDArray[np.float64]

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
    gradient : ndarray, shape (p, n)
        ``∂d/∂Q``, m/rad.
    safe : float or ndarray of shape (p,)
        ``d_safe``, m.
    describe : callable, optional
        Labels of the p rows, computed only when asked.
    usable : ndarray of bool, shape (p,), optional
        Whether each row applies (its gradient is defined); None: every row.
    """

    value: Array
    gradient: Array
    safe: float | Array
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)
    usable: NDArray[np.bool_] | None = None


def fresh_rows(count: int, n: int) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Zeroed ``(distance (count,), gradient (count, n), usable (count,))`` for a damper's
    kernel to write, as the step's own damper rows."""
    return np.zeros(count), np.zeros((count, n)), np.zeros(count, dtype=np.bool_)


class VelocityDamper(Limit):
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

    Attributes
    ----------
    quantity, unit : str
        What the distance is and its unit, for reports (``"clearance"``, ``"m"``).
    tolerance : float
        How far below ``min(d_safe, d at the start)`` an integrated step may end (its unit).
    reach : float
        A row applies only while its distance is below this (``inf``: always).
    SCENE_KEYS : dict
        dvqp's dampers: keys of the scene file's ``[constraints]`` table -> their arguments.
    """

    name = "damper"
    quantity = "distance"
    unit = "m"
    tolerance = 1e-4
    reach = math.inf
    angular = False
    """Whether the distance is the sine of an angle (verified as the angle, in rad)."""

    def __init__(self, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION) -> None:
        if not 0.0 < float(gain) <= 1.0:
            raise ParameterError("gain", f"must be in (0, 1], got {gain!r}")
        if not float(deceleration) > 0.0:
            raise ParameterError("deceleration", f"must be > 0, got {deceleration!r}")
        self.gain = float(gain)
        self.deceleration = float(deceleration)

    def distances(self, state: KinematicState) -> Distances:
        """The distances this damper keeps at ``state``, with their gradients: implement it
        for a damper of your own (the same number of distances at every state of a run)."""
        raise NotImplementedError(f"{type(self).__name__} has no distances(state)")

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """Optionally, the distances as a compiled kernel: ask for them once
        (``distance, gradient, usable = plan.damper_rows(count)``) and return a
        :class:`~dvqp.workspace.Kernel` writing ``d``, ``∂d/∂Q`` and whether each row applies
        from ``plan.state`` at every state; its safe value is then :attr:`safe`."""
        return None

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """How a limits page groups this damper's ``count`` rows into curves (the least of
        each group): ``(panel, label, rows)``; one curve by default."""
        return [(self.quantity, self.name, slice(0, count))]

    def join(self, step: StepWiring) -> None:
        """Join the run's step: a damper of your own through the run's hooks (its
        :meth:`kernel`, else :meth:`distances`); dvqp's own dampers measure their distances in
        the compiled step's tables instead. Either way its rows and their verification are the
        same compiled code."""
        step.hooked_damper(self)

    @property
    def safe(self) -> float | ArrayLike:
        """``d_safe`` of the distances of a damper with a kernel (m)."""
        raise NotImplementedError(f"{type(self).__name__} has no safe value")

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """What each distance is, for reports (``names``: the arm's guarded parts' names,
        ``names.k`` its body points, ``names.rail`` whether it has a rail point); none by
        default (a report then numbers them after :attr:`name`)."""
        return ()


@dataclass(frozen=True)
class DamperArrays:
    """Every damper row's parameters (D,): ``safe``, ``gain`` γ, ``depth`` δ (the tolerance),
    ``deceleration`` a, ``reach`` (a row applies below it) and ``angle`` (bool: verified as
    ``asin(min(d, 1))``, the tilt)."""

    safe: Array
    gain: Array
    depth: Array
    deceleration: Array
    reach: Array
    angle: NDArray[np.bool_]


@njit
def damper_value(
    distance: float, safe: float, gain: float, dt: float, depth: float, deceleration: float
) -> float:
    """The right-hand side of a damper row (see the module docstring), m/s."""
    room = distance - safe
    rhs = 0.0 if room < -depth else gain / dt * room
    if math.isinf(deceleration):
        return rhs
    low, high = -deceleration * dt, math.sqrt(2.0 * deceleration * max(room, 0.0))
    return min(max(rhs, low), high)


@njit(separate=True)
def damper_rows(params, dampers, dt: float, G: Array, h: Array) -> None:  # type: ignore[no-untyped-def]
    """Rows ``r`` of ``G``, ``h`` from damper r's distance (``dampers``, packed
    :class:`~dvqp.workspace.DamperBuffers`; ``params`` a packed :class:`DamperArrays`):
    ``−∂d/∂Q · Q̇ ≤ rhs`` where the row applies (usable, below its reach), else
    ``0 · Q̇ ≤ +inf``."""
    for r in range(params.safe.shape[0]):
        d = dampers.distance[r]
        if dampers.usable[r] and d < params.reach[r]:
            for c in range(G.shape[1]):
                G[r, c] = -dampers.gradient[r, c]
            h[r] = damper_value(
                d, params.safe[r], params.gain[r], dt, params.depth[r], params.deceleration[r]
            )
        elif h[r] != np.inf:  # (a row at +inf is a zero row already)
            for c in range(G.shape[1]):
                G[r, c] = 0.0
            h[r] = np.inf


@njit(separate=True)
def damper_values(angle, distance: Array, values: Array, start: int) -> None:  # type: ignore[no-untyped-def]
    """The verified values of the damper rows at ``values[start:]``: the distances, or the
    angle ``asin(min(d, 1))`` of an ``angle`` row."""
    for r in range(distance.shape[0]):  # a loop: a slice assignment compiles numba's
        # shape-mismatch message (string formatting), 2 s of a cold start
        values[start + r] = math.asin(min(distance[r], 1.0)) if angle[r] else distance[r]
