"""Repulsion of the body points from the obstacle circles (paper eq. 12)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import proximity
from dvqp.kinematics.state import KinematicState
from dvqp.objective import term_kernels
from dvqp.objective.term import Term, per_point, point_gains


class ObstaclePoints:
    """``Σ_j ²w_j = Σ_j Σ_i ½ w_j k̂_i e_ij``, ``k̂_i = k¹_i`` inside obstacle j, else 0.

    ``e`` is the shape's penalty (:mod:`dvqp.geometry.shapes.shape`): ``‖S_j − p_i‖² − R_j²``
    for a circle, as in the paper.

    Parameters
    ----------
    obstacles
        Shapes in (l, z) with their weights ``w_j``.
    k_obstacle
        ``k¹``, scalar or one per body point, >= 0.
    """

    name = "obstacle_points"

    def __init__(self, obstacles: ObstacleSet, k_obstacle: ArrayLike = 1.0) -> None:
        self.obstacles = ObstacleSet.of(obstacles)
        self.k_obstacle = point_gains("k_obstacle", k_obstacle)

    def evaluate(self, state: KinematicState) -> Term:
        """Value and ``Σ w k̂ ½ ∇eᵀ ∂p/∂Q`` (point Jacobian rows l, z); a circle:
        ``−Σ w k̂ (S − p)ᵀ ∂p/∂Q``."""
        obstacles = self.obstacles
        if not len(obstacles):
            return Term(0.0, np.zeros(state.n))
        near = proximity(state, obstacles).points
        k = state.k  # the body points; the probe (last guarded point) is the task's
        excess = near.penalty[:, :k]  # (J, k): e, negative inside (a circle: ‖S − p‖² − R²)
        inside = excess < 0.0
        if not inside.any():
            return Term(0.0, np.zeros(state.n))
        k1 = per_point("k_obstacle", self.k_obstacle, k)
        coef = obstacles.weights[:, None] * k1[None, :] * inside
        value = 0.5 * float(np.sum(coef * excess))
        v = (coef[..., None] * (-0.5 * near.penalty_gradient[:, :k])).sum(axis=0)  # (k, 2)
        grad = -np.einsum("kc,kcn->n", v, state.point_jacobians[:, :2, :])
        return Term(value, grad)

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """The compiled term (:func:`~dvqp.objective.term_kernels.obstacle_points`), reading
        the plan's proximity buffers; None if a shape of the set has no kernel."""
        near = plan.proximity(self.obstacles)
        if near is None:
            return None
        k1 = np.array(per_point("k_obstacle", self.k_obstacle, plan.k), dtype=np.float64)
        weights = np.array(self.obstacles.weights, dtype=np.float64)
        args = (near.point_penalty, near.point_penalty_gradient, weights, k1,
                plan.state.guarded_jacobians, np.zeros((plan.k, 2)))  # fmt: skip
        return Kernel(
            term_kernels.obstacle_points, (*args, plan.objective_value, plan.objective_gradient)
        )
