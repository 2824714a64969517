"""The objective ``w(Q)`` of the paper (eq. 10–17) and its analytic gradient.

``w`` is maximised: its gradient pulls the body points to the orbital height ``h*`` and pushes
points and links out of the obstacle circles. With ``k`` body points ``p_i = [l, z, h]``::

    ¹w   = −Σ_i ½ k²_i (h_i − h*)²
    ²w_j =  Σ_i ½ w_j k̂_i (‖S_j − p_i‖² − R_j²),   k̂_i = k¹_i inside the circle, else 0
    ³w_j =  Σ_i ½ w_j k̂_i (D_ij² − R_j²),          k̂_i = k¹_i if the closest point of link i
                                                    is interior and inside the circle
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.geometry.obstacle import Obstacle
from dvqp.geometry.proximity import ObstacleSet, proximity
from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Term:
    """A value of ``w`` (or of one of its terms) and its gradient ``∂w/∂Q``, shape (n,)."""

    value: float
    gradient: NDArray[np.float64]


@dataclass(frozen=True)
class Objective:
    """The paper's objective, configured for a robot with ``n_points`` body points.

    Parameters
    ----------
    n_points
        Number of body points k.
    orbital_level
        ``h*``, m.
    k_height
        ``k²``, scalar or shape (k,), >= 0, 1/m² scaling of the orbital term.
    k_obstacle
        ``k¹``, scalar or shape (k,), >= 0; ``k¹_i`` also weights link i (points i, i+1).
    obstacles
        Circles in the (l, z) plane (kept as an :class:`~dvqp.geometry.proximity.ObstacleSet`).
    gain
        ``λ`` that scales ``∇w`` in the resolution step (>= 0).
    """

    n_points: int
    orbital_level: float
    k_height: NDArray[np.float64] | float = 1.0
    k_obstacle: NDArray[np.float64] | float = 1.0
    obstacles: ObstacleSet | tuple[Obstacle, ...] = ()
    gain: float = 1.0

    def __post_init__(self) -> None:
        k = int(self.n_points)
        if k < 2:
            raise ParameterError("n_points", "must be >= 2")
        for name in ("k_height", "k_obstacle"):
            arr = _validate.broadcast(name, getattr(self, name), k)
            if np.any(arr < 0):
                raise ParameterError(name, "must be >= 0")
            object.__setattr__(self, name, _validate.readonly(arr))
        level = float(self.orbital_level)
        if not np.isfinite(level):
            raise ParameterError("orbital_level", "must be finite")
        object.__setattr__(self, "orbital_level", level)
        object.__setattr__(self, "gain", _validate.positive("gain", self.gain, strict=False))
        if not isinstance(self.obstacles, ObstacleSet):
            object.__setattr__(self, "obstacles", ObstacleSet(self.obstacles))

    def _check(self, state: KinematicState) -> None:
        if state.points.shape[0] != self.n_points:
            raise ShapeError("state.points", (self.n_points, 3), state.points.shape)

    def orbital(self, state: KinematicState) -> Term:
        """``¹w``: attraction of the body points to the orbital height."""
        self._check(state)
        dh = state.points[:, 2] - self.orbital_level
        kh = np.asarray(self.k_height)
        value = -0.5 * float(kh @ (dh * dh))
        grad = -(kh * dh) @ state.point_jacobians[:, 2, :]
        return Term(value, grad)

    def obstacle_points(self, state: KinematicState) -> Term:
        """``Σ_j ²w_j``: repulsion of the body points from the obstacles."""
        self._check(state)
        obstacles = self.obstacles
        if not len(obstacles):
            return Term(0.0, np.zeros(state.n))
        near = proximity(state, obstacles)
        excess = near.point_distance**2 - obstacles.radii[:, None] ** 2  # (J, k)
        inside = excess < 0.0
        if not inside.any():
            return Term(0.0, np.zeros(state.n))
        coef = obstacles.weights[:, None] * np.asarray(self.k_obstacle)[None, :] * inside
        value = 0.5 * float(np.sum(coef * excess))
        # ∂/∂Q: −Σ w k̂ (S − p)ᵀ ∂p/∂Q   (point Jacobian rows l, z)
        v = (coef[..., None] * near.point_offsets).sum(axis=0)  # (k, 2)
        grad = -np.einsum("kc,kcn->n", v, state.point_jacobians[:, :2, :])
        return Term(value, grad)

    def obstacle_links(self, state: KinematicState) -> Term:
        """``Σ_j ³w_j``: repulsion of the links (closest interior point) from the obstacles."""
        self._check(state)
        obstacles = self.obstacles
        if not len(obstacles):
            return Term(0.0, np.zeros(state.n))
        near = proximity(state, obstacles)
        t = near.link_t
        excess = near.link_distance**2 - obstacles.radii[:, None] ** 2  # (J, k-1)
        active = (excess < 0.0) & (t > 0.0) & (t < 1.0)
        if not active.any():
            return Term(0.0, np.zeros(state.n))
        coef = obstacles.weights[:, None] * np.asarray(self.k_obstacle)[None, :-1] * active
        value = 0.5 * float(np.sum(coef * excess))
        # ∂³w/∂Q = −Σ w k̂ (S − p̄)ᵀ ((1−t) ∂p_i + t ∂p_{i+1}); the ∂t term vanishes (r ⟂ link)
        a = coef[..., None] * near.link_offsets  # (J, k-1, 2)
        per_point = np.zeros((self.n_points, 2))
        per_point[:-1] += (a * (1.0 - t)[..., None]).sum(axis=0)
        per_point[1:] += (a * t[..., None]).sum(axis=0)
        grad = -np.einsum("kc,kcn->n", per_point, state.point_jacobians[:, :2, :])
        return Term(value, grad)

    def evaluate(self, state: KinematicState) -> Term:
        """``w(Q)`` and ``∂w/∂Q`` (all three terms), shape (n,)."""
        terms = (self.orbital(state), self.obstacle_points(state), self.obstacle_links(state))
        return Term(
            sum(t.value for t in terms), terms[0].gradient + terms[1].gradient + terms[2].gradient
        )
