"""Repulsion of the body points from the obstacles (paper eq. 12)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import measure_state
from dvqp.kinematics.state import KinematicState
from dvqp.objective.term import Array, ObjectiveTerm, Term, per_point, point_gains, pull_points
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class ObstaclePoints(ObjectiveTerm):
    """``Σ_j ²w_j = Σ_j Σ_i ½ w_j k̂_i e_ij``, ``k̂_i = k¹_i`` inside obstacle j, else 0
    (compiled: :func:`obstacle_points`).

    ``e`` is the shape's penalty (:mod:`dvqp.geometry.shapes.shape`): ``‖S_j − p_i‖² − R_j²``
    for a circle, as in the paper; of the distance to the obstacle's solid where it has a
    height, so that a point inside a low obstacle is pushed up or sideways, whichever face is
    nearer.

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

    @property
    def measured(self) -> ObstacleSet:
        """Its obstacles."""
        return self.obstacles

    def evaluate(self, state: KinematicState) -> Term:
        """What :func:`obstacle_points` adds at ``state``."""
        near, value, gradient = measure_state(state, self.obstacles), np.zeros(1), np.zeros(state.n)
        gains = per_point("k_obstacle", self.k_obstacle, state.k)
        obstacle_points(
            near.point_penalty,
            near.point_penalty_gradient,
            near.skipped,
            self.obstacles.weights[:, None] * gains[None, :],
            state.guarded_jacobians,
            np.zeros((state.k, 3)),
            value,
            gradient,
        )
        return Term(float(value[0]), gradient)

    def join(self, step: StepWiring) -> None:
        """Its coefficients ``w_j k¹_i`` in the compiled objective's tables."""
        if overrides(self, ObstaclePoints, "evaluate", "kernel"):
            return super().join(step)
        gains = per_point("k_obstacle", self.k_obstacle, step.plan.k)
        coef = self.obstacles.weights[:, None] * gains[None, :]
        step.point_coefficients(step.rows_of(self.obstacles), coef)
        return None


@njit(separate=True)
def obstacle_points(
    penalty: Array,
    penalty_gradient: Array,
    skipped: Array,
    coef: Array,
    jacobians: Array,
    at_points: Array,
    value: Array,
    gradient: Array,
) -> None:
    """Add ``Σ_j Σ_i ½ c_ji e_ji`` over the body points inside obstacle j (``e < 0``) to
    ``value`` and ``Σ ½ c ∇eᵀ ∂p/∂Q`` to ``gradient``. ``penalty`` (J, k+1) and
    ``penalty_gradient`` (J, k+1, 3, with respect to ``[l, z, h]``) are the guarded points';
    ``coef`` (J, k) is ``w_j k¹_i`` (0 for an obstacle the term does not see); an obstacle
    ``skipped`` (J,) by the broad phase is outside; ``at_points`` (k, 3) is scratch."""
    k = coef.shape[1]
    at_points[:, :] = 0.0
    total = 0.0
    for j in range(coef.shape[0]):
        if skipped[j]:
            continue
        for i in range(k):
            e, c = penalty[j, i], coef[j, i]
            if e < 0.0 and c != 0.0:
                total += c * e
                at_points[i, 0] += c * (-0.5 * penalty_gradient[j, i, 0])
                at_points[i, 1] += c * (-0.5 * penalty_gradient[j, i, 1])
                at_points[i, 2] += c * (-0.5 * penalty_gradient[j, i, 2])
    value[0] += 0.5 * total
    pull_points(at_points, jacobians, gradient)
