"""The objective's terms in NumPy, as dvqp computed them before its redesign
(``git show 170077d:dvqp/objective/...``), to check the compiled objective against.

The penalties ``e`` and their gradients come from :func:`dvqp.geometry.proximity` (the shapes
have their own tests); the sums, gains, activity rules and the chain to ``∂w/∂Q`` are the old
formulas.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from dvqp import KinematicState, Term
from dvqp.geometry import proximity
from dvqp.objective import ObstacleLinks, ObstaclePoints, OrbitalLevel

Array = NDArray[np.float64]


def gains(value: Array, k: int) -> Array:
    """A scalar or per-point gain for k body points."""
    return np.full(k, float(value)) if np.ndim(value) == 0 else np.asarray(value, dtype=float)


def orbital_level(term: OrbitalLevel, state: KinematicState) -> Term:
    """``−Σ_i ½ k²_i (h_i − h*)²`` and ``−Σ_i k²_i (h_i − h*) ∂h_i/∂Q``."""
    dh = state.points[:, 2] - term.level
    kh = gains(term.k_height, state.k)
    return Term(-0.5 * float(kh @ (dh * dh)), -(kh * dh) @ state.point_jacobians[:, 2, :])


def obstacle_points(term: ObstaclePoints, state: KinematicState) -> Term:
    """``Σ_j Σ_i ½ w_j k¹_i e_ij`` over the body points inside obstacle j (``e < 0``)."""
    if not len(term.obstacles):
        return Term(0.0, np.zeros(state.n))
    near = proximity(state, term.obstacles).points
    k = state.k  # the body points; the probe (last guarded point) is the task's
    excess = near.penalty[:, :k]
    coef = term.obstacles.weights[:, None] * gains(term.k_obstacle, k)[None, :] * (excess < 0.0)
    v = (coef[..., None] * (-0.5 * near.penalty_gradient[:, :k])).sum(axis=0)  # (k, 3)
    grad = -np.einsum("kc,kcn->n", v, state.point_jacobians[:, :3, :])
    return Term(0.5 * float(np.sum(coef * excess)), grad)


def obstacle_links(term: ObstacleLinks, state: KinematicState) -> Term:
    """``Σ_j Σ_i ½ w_j k¹_i e_ij`` over the body links whose closest point is interior and
    inside obstacle j; the gradient shared by the link's ends as ``(1 − t, t)`` (its h part,
    to an obstacle with a height, as ``(1 − t_height, t_height)``)."""
    if not len(term.obstacles):
        return Term(0.0, np.zeros(state.n))
    near = proximity(state, term.obstacles).links
    k = state.k  # the body links; the holder (last guarded link) is left to the dampers
    t = near.t[:, : k - 1]
    t_height = near.t_height[:, : k - 1]  # where the h part holds (t, for an unbounded one)
    excess = near.penalty[:, : k - 1]
    active = (excess < 0.0) & (t > 0.0) & (t < 1.0)
    coef = term.obstacles.weights[:, None] * gains(term.k_obstacle, k)[None, :-1] * active
    a = coef[..., None] * (-0.5 * near.penalty_gradient[:, : k - 1])  # (J, k-1, 3)
    share = np.stack([t, t, t_height], axis=-1)
    at_points = np.zeros((k, 3))
    at_points[:-1] += (a * (1.0 - share)).sum(axis=0)
    at_points[1:] += (a * share).sum(axis=0)
    grad = -np.einsum("kc,kcn->n", at_points, state.point_jacobians[:, :3, :])
    return Term(0.5 * float(np.sum(coef * excess)), grad)


def evaluate(term: object, state: KinematicState) -> Term:
    """One of dvqp's terms, or a user's (its own ``evaluate``)."""
    if type(term) is OrbitalLevel:
        return orbital_level(term, state)
    if type(term) is ObstaclePoints:
        return obstacle_points(term, state)
    if type(term) is ObstacleLinks:
        return obstacle_links(term, state)
    return term.evaluate(state)  # type: ignore[attr-defined, no-any-return]


def total(terms: tuple[object, ...], state: KinematicState) -> Term:
    """The sum of the terms."""
    parts = [evaluate(t, state) for t in terms]
    return Term(sum(p.value for p in parts), sum((p.gradient for p in parts), np.zeros(state.n)))
