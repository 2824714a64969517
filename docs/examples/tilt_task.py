"""A user-written soft task: hold the probe's last link at a chosen tilt to the pipe surface.

The tilt θ is the angle between the probe axis ``a`` (the tool frame's z axis) and the radial
direction ``r̂`` at the tool, ``cos θ = a · r̂``. The task asks ``cos θ`` to move toward
``cos θ*`` at the rate ``K (cos θ* − cos θ)``, as a cost of weight ``w`` (a soft task: the tool's
DV task and every limit come first). Its Jacobian row, with ``ȧ = ω × a`` and
``∂r̂/∂O = (P − r̂ r̂ᵀ)/ρ`` (P drops the pipe-axis component)::

    ∂ cos θ / ∂Q = (a × r̂)ᵀ J_ω + aᵀ (P − r̂ r̂ᵀ) J_v / ρ
"""

from __future__ import annotations

import math

import numpy as np

from dvqp import KinematicState, Task, TaskRows


class TiltTask(Task):
    """Soft task: the probe's tilt from the radial direction toward ``tilt`` (rad).

    Parameters
    ----------
    tilt
        θ*, rad, in [0, π].
    gain
        K, 1/s.
    weight
        w of the cost (relative to the joint metric W).
    """

    name = "tilt"
    hard = False

    def __init__(self, tilt: float, gain: float = 2.0, weight: float = 1.0) -> None:
        self.target = math.cos(tilt)
        self.gain = gain
        self.weight = weight

    @staticmethod
    def cos_tilt(state: KinematicState) -> tuple[float, np.ndarray]:
        """``cos θ`` and its row ``∂ cos θ / ∂Q``, shape (n,)."""
        t = state.k  # the tool: the guarded frame after the k body points
        origin, axis, jac = state.origins[t], state.axes[t], state.frame_jacobians[t]
        rho = math.hypot(origin[0], origin[1])
        radial = np.array([origin[0] / rho, origin[1] / rho, 0.0])
        planar = np.diag([1.0, 1.0, 0.0]) - np.outer(radial, radial)
        row = np.cross(axis, radial) @ jac[3:] + axis @ planar @ jac[:3] / rho
        return float(axis @ radial), row

    def compute(self, state: KinematicState, command: np.ndarray, dt: float) -> TaskRows:
        """One row: ``∂cos θ/∂Q · Q̇ ≈ K (cos θ* − cos θ)``."""
        value, row = self.cos_tilt(state)
        return TaskRows(row[None, :], np.array([self.gain * (self.target - value)]), self.weight)
