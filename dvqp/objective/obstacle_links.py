"""Repulsion of the links from the obstacle circles (paper eq. 13–15)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import proximity
from dvqp.kinematics.state import KinematicState
from dvqp.objective import term_kernels
from dvqp.objective.term import Term, per_point, point_gains


class ObstacleLinks:
    """``Σ_j ³w_j = Σ_j Σ_i ½ w_j k̂_i e_ij`` over the links ``[p_i, p_{i+1}]``.

    ``e_ij`` is obstacle j's penalty at the closest point of link i (a circle:
    ``D_ij² − R_j²``); ``k̂_i = k¹_i`` where that point is interior and inside, else 0.

    Parameters
    ----------
    obstacles
        Shapes in (l, z) with their weights ``w_j``.
    k_obstacle
        ``k¹``, scalar or one per body point (link i takes ``k¹_i``), >= 0.
    """

    name = "obstacle_links"

    def __init__(self, obstacles: ObstacleSet, k_obstacle: ArrayLike = 1.0) -> None:
        self.obstacles = ObstacleSet.of(obstacles)
        self.k_obstacle = point_gains("k_obstacle", k_obstacle)

    def evaluate(self, state: KinematicState) -> Term:
        """Value and ``Σ w k̂ ½ ∇eᵀ ((1−t) ∂p_i + t ∂p_{i+1})`` (the ∂t term vanishes)."""
        obstacles = self.obstacles
        if not len(obstacles):
            return Term(0.0, np.zeros(state.n))
        near = proximity(state, obstacles).links
        k = state.k  # the body links; the holder (last guarded link) is left to the dampers
        t = near.t[:, : k - 1]
        excess = near.penalty[:, : k - 1]  # (J, k-1): e at the closest point
        active = (excess < 0.0) & (t > 0.0) & (t < 1.0)
        if not active.any():
            return Term(0.0, np.zeros(state.n))
        k1 = per_point("k_obstacle", self.k_obstacle, k)
        coef = obstacles.weights[:, None] * k1[None, :-1] * active
        value = 0.5 * float(np.sum(coef * excess))
        a = coef[..., None] * (-0.5 * near.penalty_gradient[:, : k - 1])  # (J, k-1, 2)
        at_points = np.zeros((k, 2))
        at_points[:-1] += (a * (1.0 - t)[..., None]).sum(axis=0)
        at_points[1:] += (a * t[..., None]).sum(axis=0)
        grad = -np.einsum("kc,kcn->n", at_points, state.point_jacobians[:, :2, :])
        return Term(value, grad)

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """The compiled term (:func:`~dvqp.objective.term_kernels.obstacle_links`), reading
        the plan's proximity buffers; None if a shape of the set has no kernel."""
        near = plan.proximity(self.obstacles)
        if near is None:
            return None
        k1 = np.array(per_point("k_obstacle", self.k_obstacle, plan.k), dtype=np.float64)
        weights = np.array(self.obstacles.weights, dtype=np.float64)
        args = (near.link_penalty, near.link_penalty_gradient, near.link_t, weights, k1,
                plan.state.guarded_jacobians, np.zeros((plan.k, 2)))  # fmt: skip
        return Kernel(
            term_kernels.obstacle_links, (*args, plan.objective_value, plan.objective_gradient)
        )
