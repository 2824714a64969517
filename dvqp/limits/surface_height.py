"""The body points stay above a minimum height over the pipe surface."""

from __future__ import annotations

import numpy as np

from dvqp.limits.limit import Constraint
from dvqp.limits.obstacle_damper import DamperParameters
from dvqp.kinematics.state import KinematicState


def surface_height(state: KinematicState, params: DamperParameters, dt: float) -> Constraint:
    """``h_i ≥ h_min`` for every body point, linearised one step ahead as a damper::

        ∂h_i/∂Q · Q̇ ≥ −γ (h_i − h_min)/dt      i.e.   −∂h_i/∂Q · Q̇ ≤ γ (h_i − h_min)/dt

    A point already below ``h_min`` may not descend further (right-hand side clipped at 0).

    Returns
    -------
    Constraint
        k rows (one per body point), ``h`` in m/s, labels ``"point3/height"``.
    """
    h = state.points[:, 2]
    rhs = np.maximum(params.gain / dt * (h - params.min_height), 0.0)
    k = h.shape[0]
    return Constraint(
        -state.point_jacobians[:, 2, :],
        rhs,
        lambda: tuple(f"point{i + 1}/height" for i in range(k)),
    )
