"""Velocity dampers that keep body points and links out of the obstacle circles.

For a pair (body point or link, obstacle j) with signed clearance ``d = ‖S_j − p‖ − R_j`` (m)
below the influence distance ``d_i``, one row::

    ∇d · Q̇ ≥ −γ (d − d_safe) / dt          written as   −∇d · Q̇ ≤ γ (d − d_safe) / dt

so ``d`` decays at most geometrically toward ``d_safe`` and never crosses it at first order.
A pair already closer than ``d_safe`` (e.g. a body that starts inside an obstacle) gets the
right-hand side 0: it may not approach further, and ``∇w`` pushes it out, instead of a demand to
escape at ``γ (d_safe − d)/dt`` that the velocity limits could not meet. A link row is added only
where its closest point is interior; at an end the point's own row holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dvqp import _validate
from dvqp.limits.limit import Constraint
from dvqp.errors import ParameterError
from dvqp.geometry.proximity import ObstacleSet, proximity
from dvqp.kinematics.state import KinematicState

_TINY = 1e-12


@dataclass(frozen=True)
class DamperParameters:
    """Parameters of the QP's inequality rows.

    Parameters
    ----------
    min_height
        ``h_min``, m: lowest height of a body point above the pipe surface.
    margin
        ``d_safe``, m, >= 0: clearance the dampers keep from an obstacle circle.
    influence
        ``d_i``, m, > margin: pairs farther than this add no row.
    gain
        ``γ`` in (0, 1].
    """

    min_height: float = 0.0
    margin: float = 0.01
    influence: float = 0.06
    gain: float = 0.5

    def __post_init__(self) -> None:
        if not np.isfinite(self.min_height):
            raise ParameterError("min_height", "must be finite")
        _validate.positive("margin", self.margin, strict=False)
        if not float(self.influence) > float(self.margin) or not np.isfinite(self.influence):
            raise ParameterError("influence", "must be finite and > margin")
        if not 0.0 < float(self.gain) <= 1.0:
            raise ParameterError("damper_gain", f"must be in (0, 1], got {self.gain!r}")


def obstacle_dampers(
    state: KinematicState, obstacles: ObstacleSet, params: DamperParameters, dt: float
) -> Constraint:
    """Damper rows for every body point and every link near every obstacle.

    Parameters
    ----------
    state
        Kinematics of this step.
    obstacles
        Circles in (l, z).
    params
        Margin, influence and gain.
    dt
        Step, s.

    Returns
    -------
    Constraint
        ``G`` (p, n), ``h`` (p,) in m/s, labels ``"point3/obstacle1"``, ``"link2/obstacle1"``.
    """
    n = state.n
    if not len(obstacles):
        return Constraint.empty(n)
    near = proximity(state, obstacles)
    jac = state.point_jacobians[:, :2, :]  # (k, 2, n)
    rate = params.gain / dt
    # Points: −∇d = (S − p)ᵀ/‖S − p‖ · ∂p/∂Q
    dist, clearance = near.point_distance, near.point_clearance
    pj, pi = np.nonzero((clearance < params.influence) & (dist > _TINY))
    unit = near.point_offsets[pj, pi] / dist[pj, pi, None]  # (p, 2)
    point_rows = (unit[:, :, None] * jac[pi]).sum(axis=1)
    point_rhs = rate * (clearance[pj, pi] - params.margin)
    # Links: −∇d = (S − p̄)ᵀ/‖S − p̄‖ · ((1 − t) ∂p_i + t ∂p_{i+1}), interior closest points only
    t, dist, clearance = near.link_t, near.link_distance, near.link_clearance
    lj, li = np.nonzero((clearance < params.influence) & (dist > _TINY) & (t > 0.0) & (t < 1.0))
    unit = near.link_offsets[lj, li] / dist[lj, li, None]
    tt = t[lj, li, None, None]
    link_rows = (unit[:, :, None] * ((1.0 - tt) * jac[li] + tt * jac[li + 1])).sum(axis=1)
    link_rhs = rate * (clearance[lj, li] - params.margin)

    def describe() -> tuple[str, ...]:
        points = [f"point{i + 1}/obstacle{j + 1}" for j, i in zip(pj, pi, strict=True)]
        links = [f"link{i + 1}/obstacle{j + 1}" for j, i in zip(lj, li, strict=True)]
        return (*points, *links)

    G = np.concatenate([point_rows, link_rows])
    h = np.maximum(np.concatenate([point_rhs, link_rhs]), 0.0)
    return Constraint(G, h, describe)
