"""A tilt limit that keeps the probe's heading defined.

The heading α of the tool is the direction of the probe axis ``a`` projected on the pipe's
tangent plane; it is undefined when ``a`` is radial. With the tilt θ the angle between ``a``
and the radial direction ``r̂`` at the tool, the projection has length ``sin θ``. The limit keeps
``d = sin θ ≥ sin θ_min`` as a damper row. With ``u = cos θ = a · r̂``, ``ȧ = ω × a`` and
``∂r̂/∂O = (P − r̂ r̂ᵀ)/ρ`` (``P`` drops the pipe-axis component, ``ρ`` the distance from it)::

    ∂u/∂Q = (a × r̂)ᵀ J_ω + aᵀ (P − r̂ r̂ᵀ) J_v / ρ,        ∂d/∂Q = −(u / d) ∂u/∂Q
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.damper_kernels import tilt_rows, tilt_value
from dvqp.limits.excess import Excess
from dvqp.limits.limit import Constraint

_SIN_FLOOR = 1e-9


def tilt_cosine(state: KinematicState) -> tuple[float, NDArray[np.float64]]:
    """``u = cos θ`` of the probe axis to the radial direction, and ``∂u/∂Q``, shape (n,)."""
    origin, axis, jac = state.origins[-1], state.axes[-1], state.frame_jacobians[-1]
    rho = math.hypot(origin[0], origin[1])
    rx, ry = origin[0] / rho, origin[1] / rho
    ax, ay, az = axis.tolist()
    u = ax * rx + ay * ry
    # (a × r̂)ᵀ J_ω + aᵀ (P − r̂ r̂ᵀ) J_v / ρ, with r̂ = (rx, ry, 0)
    cross = np.array([-az * ry, az * rx, ax * ry - ay * rx])
    tangential = np.array([(ax - u * rx) / rho, (ay - u * ry) / rho, 0.0])
    return u, cross @ jac[3:] + tangential @ jac[:3]


def tilt_sine(state: KinematicState) -> float:
    """``sin θ``: length of the probe axis' projection on the pipe's tangent plane."""
    origin, axis = state.origins[-1], state.axes[-1]
    rho = math.hypot(origin[0], origin[1])
    u = (axis[0] * origin[0] + axis[1] * origin[1]) / rho
    return math.sqrt(max(1.0 - u * u, 0.0))


def tilt(state: KinematicState) -> float:
    """The probe's tilt θ from the radial direction, rad, in [0, π]."""
    origin, axis = state.origins[-1], state.axes[-1]
    u = (axis[0] * origin[0] + axis[1] * origin[1]) / math.hypot(origin[0], origin[1])
    return math.acos(max(-1.0, min(1.0, u)))


class TiltLimit(VelocityDamper):
    """Keeps the probe axis at least ``min_tilt`` away from the radial direction (both ways).

    Parameters
    ----------
    min_tilt
        ``θ_min``, rad, in [0, π/2); 0 turns the limit off.
    gain
        ``γ`` in (0, 1].
    """

    name = "tilt"
    quantity = "tilt"
    tolerance = 1e-3
    """rad: how far below ``min(θ_min, θ at the start)`` an integrated step may end."""
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "min_tilt": "min_tilt",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, min_tilt: float = 0.2, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        if not 0.0 <= float(min_tilt) < 0.5 * math.pi:
            raise ParameterError("min_tilt", f"must be in [0, π/2) rad, got {min_tilt!r}")
        self.min_tilt = float(min_tilt)

    def distances(self, state: KinematicState) -> Distances:
        """``d = sin θ`` (the probe axis' projection on the tangent plane) and ``∂d/∂Q``."""
        u, du = tilt_cosine(state)
        d = math.sqrt(max(1.0 - u * u, 0.0))
        gradient = (-u / max(d, _SIN_FLOOR)) * du
        return Distances(
            np.array([d]), gradient[None, :], math.sin(self.min_tilt), lambda: ("probe/tilt",)
        )

    def all_distances(self, state: KinematicState) -> Distances:
        """``sin θ`` alone (no gradient), for verification."""
        return Distances(np.array([tilt_sine(state)]), None, math.sin(self.min_tilt))

    def compute(self, state: KinematicState, dt: float) -> Constraint:
        """One damper row, or none when the limit is off (``min_tilt = 0``)."""
        if self.min_tilt == 0.0:
            return Constraint.empty(state.n)
        return super().compute(state, dt)

    def excess(self, start: KinematicState, state: KinematicState) -> Excess:
        """How far the tilt is below ``min(θ_min, θ at the start)``, rad (θ from 0 to π/2)."""
        if self.min_tilt == 0.0:
            return Excess(-math.inf, self.tolerance)
        found = super().excess(start, state)
        actual, bound = math.asin(min(found.actual, 1.0)), math.asin(min(found.bound, 1.0))
        label = "probe/tilt" if bound - actual > 0.0 else ""
        return Excess(bound - actual, self.tolerance, label, "tilt", "rad", actual, bound)

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """The probe's tilt row from ``plan.state``; None when the limit is off."""
        if self.min_tilt == 0.0:
            return None
        G, h = plan.constraint_rows(1)
        s, params = plan.state, self.params(math.sin(self.min_tilt))
        return Kernel(tilt_rows, (s.origins, s.axes, s.frame_jacobians, params, plan.dt, G, h))

    def verifier(self, plan: StepPlan) -> Kernel | None:
        """The tilt ``asin(min(sin θ, 1))``, rad, safe value ``asin(min(sin θ_min, 1))``
        (the folding :meth:`excess` uses); None when the limit is off."""
        if self.min_tilt == 0.0:
            return None
        safe = math.asin(min(math.sin(self.min_tilt), 1.0))
        slot = plan.verified(self, 1, safe, self.tolerance)
        return Kernel(tilt_value, (plan.state.origins, plan.state.axes, slot))
