"""Repulsion of the links from the obstacles (paper eq. 13–15)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.geometry.obstacle import ObstacleSet
from dvqp.geometry.proximity import measure_state
from dvqp.kinematics.state import KinematicState
from dvqp.objective.term import Array, ObjectiveTerm, Term, per_point, point_gains, pull_points
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class ObstacleLinks(ObjectiveTerm):
    """``Σ_j ³w_j = Σ_j Σ_i ½ w_j k̂_i e_ij`` over the body links ``[p_i, p_{i+1}]``
    (compiled: :func:`obstacle_links`).

    ``e_ij`` is obstacle j's penalty at the closest point of link i (a circle:
    ``D_ij² − R_j²``); ``k̂_i = k¹_i`` where that point is interior and inside, else 0. The
    probe holder (the last guarded link) is left to the dampers.

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

    @property
    def measured(self) -> ObstacleSet:
        """Its obstacles."""
        return self.obstacles

    def evaluate(self, state: KinematicState) -> Term:
        """What :func:`obstacle_links` adds at ``state``."""
        near, value, gradient = measure_state(state, self.obstacles), np.zeros(1), np.zeros(state.n)
        gains = per_point("k_obstacle", self.k_obstacle, state.k)
        obstacle_links(
            near.link_penalty,
            near.link_penalty_gradient,
            near.skipped,
            near.link_penalty_at,
            (self.obstacles.weights[:, None] * gains[None, :])[:, :-1],
            state.guarded_jacobians,
            np.zeros((state.k, 3)),
            value,
            gradient,
        )
        return Term(float(value[0]), gradient)

    def join(self, step: StepWiring) -> None:
        """Its coefficients ``w_j k¹_i`` in the compiled objective's tables."""
        if overrides(self, ObstacleLinks, "evaluate", "kernel"):
            return super().join(step)
        gains = per_point("k_obstacle", self.k_obstacle, step.plan.k)
        coef = self.obstacles.weights[:, None] * gains[None, :]
        step.link_coefficients(step.rows_of(self.obstacles), coef[:, :-1])
        return None


@njit(separate=True)
def obstacle_links(
    penalty: Array,
    penalty_gradient: Array,
    skipped: Array,
    at: Array,
    coef: Array,
    jacobians: Array,
    at_points: Array,
    value: Array,
    gradient: Array,
) -> None:
    """Add ``Σ_j Σ_i ½ c_ji e_ji`` over the body links whose closest point is interior
    (``0 < t < 1``) and inside obstacle j to ``value``, the gradient shared by the link's ends
    as ``(1 − t, t)`` (the ∂t term vanishes). ``penalty`` (J, k) and ``penalty_gradient``
    (J, k, 3) are the guarded links', ``at`` (J, k, 2) the link parameters their [l, z] part
    and their h part hold at (the same but for an obstacle with a height; a link is interior
    if either is); ``coef`` (J, k − 1) is ``w_j k¹_i``; an obstacle ``skipped`` (J,) by the
    broad phase is outside; ``at_points`` (k, 3) is scratch."""
    at_points[:, :] = 0.0
    total = 0.0
    for j in range(coef.shape[0]):
        if skipped[j]:
            continue
        for i in range(coef.shape[1]):
            e, t, th, c = penalty[j, i], at[j, i, 0], at[j, i, 1], coef[j, i]
            if e < 0.0 and ((t > 0.0 and t < 1.0) or (th > 0.0 and th < 1.0)) and c != 0.0:
                total += c * e
                al = c * (-0.5 * penalty_gradient[j, i, 0])
                az = c * (-0.5 * penalty_gradient[j, i, 1])
                ah = c * (-0.5 * penalty_gradient[j, i, 2])
                at_points[i, 0] += al * (1.0 - t)
                at_points[i, 1] += az * (1.0 - t)
                at_points[i + 1, 0] += al * t
                at_points[i + 1, 1] += az * t
                at_points[i, 2] += ah * (1.0 - th)
                at_points[i + 1, 2] += ah * th
    value[0] += 0.5 * total
    pull_points(at_points, jacobians, gradient)
