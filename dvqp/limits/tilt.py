"""A tilt limit that keeps the probe's heading defined.

The heading α of the tool is the direction of the probe axis ``a`` projected on the pipe's
tangent plane; it is undefined when ``a`` is radial. With the tilt θ the angle between ``a``
and the radial direction ``r̂`` at the tool, the projection has length ``sin θ``. The limit keeps
``d = sin θ ≥ sin θ_min`` as a damper row, and is verified on the angle
``asin(min(sin θ, 1))``. With ``u = cos θ = a · r̂``, ``ȧ = ω × a`` and
``∂r̂/∂O = (P − r̂ r̂ᵀ)/ρ`` (``P`` drops the pipe-axis component, ``ρ`` the distance from it)::

    ∂u/∂Q = (a × r̂)ᵀ J_ω + aᵀ (P − r̂ r̂ᵀ) J_v / ρ,        ∂d/∂Q = −(u / d) ∂u/∂Q
"""

from __future__ import annotations

import math
from typing import ClassVar

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper, fresh_rows
from dvqp.workspace import PartNames
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit

SIN_FLOOR = 1e-9
"""The smallest ``sin θ`` the gradient divides by (the axis radial)."""


class TiltLimit(VelocityDamper):
    """Keeps the probe axis at least ``min_tilt`` away from the radial direction (both ways;
    compiled: :func:`tilt_distance`).

    Parameters
    ----------
    min_tilt
        ``θ_min``, rad, in [0, π/2); 0 turns the limit off.
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, 1/s².
    """

    name = "tilt"
    quantity = "tilt"
    unit = "rad"
    tolerance = 1e-3
    """rad: how far below ``min(θ_min, θ at the start)`` an integrated step may end."""
    angular = True
    IN_EVERY_SCENE = True
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "min_tilt": "min_tilt",
        "damper_gain": "gain",
    }

    def __init__(
        self, min_tilt: float = 0.2, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        if not 0.0 <= float(min_tilt) < 0.5 * math.pi:
            raise ParameterError("min_tilt", f"must be in [0, π/2) rad, got {min_tilt!r}")
        self.min_tilt = float(min_tilt)

    @property
    def safe(self) -> float:
        """``sin θ_min``."""
        return math.sin(self.min_tilt)

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``("probe/tilt",)``, by the probe's name."""
        return (f"{names.probe}/tilt",)

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """One curve: the probe axis's angle from the radial."""
        return [("tilt", "probe from radial", slice(0, count))]

    def distances(self, state: KinematicState) -> Distances:
        """The row :func:`tilt_distance` writes at ``state``: ``sin θ`` of the probe."""
        distance, gradient, usable = fresh_rows(1, state.n)
        frames = state.frame_jacobians
        tilt_distance(state.origins, state.axes, frames, state.k, 0, distance, gradient, usable)
        labels = self.labels(state.part_names)
        return Distances(distance, gradient, self.safe, lambda: labels, usable)

    def join(self, step: StepWiring) -> None:
        """One row, ``sin θ``, measured by :func:`tilt_distance` (none if ``θ_min = 0``)."""
        if self.min_tilt == 0.0:
            return None
        if overrides(self, TiltLimit, "distances", "kernel"):
            return super().join(step)
        step.measures["tilts"].append(step.damper(self, 1, self.labels(step.plan.names)))
        return None


@njit
def tilt_cosine(origins, axes, frame_jacobians, m, du) -> float:  # type: ignore[no-untyped-def]
    """``u = cos θ`` of the probe (guarded frame ``m``) and ``∂u/∂Q`` into ``du`` (n,)."""
    jac = frame_jacobians[m]
    rho = math.hypot(origins[m, 0], origins[m, 1])
    rx, ry = origins[m, 0] / rho, origins[m, 1] / rho
    ax, ay, az = axes[m, 0], axes[m, 1], axes[m, 2]
    u = ax * rx + ay * ry
    c0, c1, c2 = -az * ry, az * rx, ax * ry - ay * rx
    t0, t1 = (ax - u * rx) / rho, (ay - u * ry) / rho
    for c in range(du.shape[0]):
        du[c] = c0 * jac[3, c] + c1 * jac[4, c] + c2 * jac[5, c] + t0 * jac[0, c] + t1 * jac[1, c]
    return u


@njit(separate=True)
def tilt_distance(origins, axes, frame_jacobians, m, row, distance, gradient, usable) -> None:  # type: ignore[no-untyped-def]
    """Row ``row``: ``d = sin θ`` of the probe (frame ``m``) and
    ``∂d/∂Q = −(u / max(d, ε)) ∂u/∂Q``."""
    du = gradient[row]
    u = tilt_cosine(origins, axes, frame_jacobians, m, du)
    d = math.sqrt(max(1.0 - u * u, 0.0))
    scale = -u / max(d, SIN_FLOOR)
    for c in range(du.shape[0]):
        du[c] = scale * du[c]
    distance[row], usable[row] = d, True


@njit(separate=True)
def tilt_angle(origins, axes, m) -> float:  # type: ignore[no-untyped-def]
    """The tilt θ of the probe (guarded frame ``m``) from the radial direction, rad, in
    [0, π]."""
    ox, oy = origins[m, 0], origins[m, 1]
    u = (axes[m, 0] * ox + axes[m, 1] * oy) / math.hypot(ox, oy)
    return math.acos(max(-1.0, min(1.0, u)))
