"""Compiled (numba) objective terms: each ADDS its value and gradient ``∂w/∂Q`` to the plan's.

The engine zeroes ``value`` (1,) and ``gradient`` (n,) once per state, then calls every term's
kernel (:meth:`~dvqp.objective.objective.Objective.kernels`); the objective's gain ``λ`` is
applied by the engine. Each kernel does the arithmetic of its term's ``evaluate`` one body
point at a time, reading the plan's kinematics (``guarded`` (k+1, 3), ``jacobians``
(k+1, 3, n), the body points being the first k) and proximity buffers (rows: obstacles).
"""

from __future__ import annotations

from numba import njit

from dvqp.geometry.shapes.shape import Array


@njit(cache=True)
def orbital_level(
    guarded: Array, jacobians: Array, level: float, k_height: Array, value: Array,
    gradient: Array,
) -> None:  # fmt: skip
    """``¹w = −Σ_i ½ k²_i (h_i − h*)²`` and ``−Σ_i k²_i (h_i − h*) ∂h_i/∂Q`` over the k body
    points (``k_height`` (k,), 1/m²; ``level`` h*, m)."""
    total = 0.0
    for i in range(k_height.shape[0]):
        dh = guarded[i, 2] - level
        total += k_height[i] * (dh * dh)
        c = k_height[i] * dh
        for col in range(gradient.shape[0]):
            gradient[col] -= c * jacobians[i, 2, col]
    value[0] += -0.5 * total


@njit(cache=True)
def _chain(at_points: Array, jacobians: Array, gradient: Array) -> None:
    """``gradient −= Σ_i at_points[i] · ∂[l, z]_i/∂Q`` over the k body points."""
    for i in range(at_points.shape[0]):
        al, az = at_points[i, 0], at_points[i, 1]
        if al == 0.0 and az == 0.0:
            continue
        for col in range(gradient.shape[0]):
            gradient[col] -= al * jacobians[i, 0, col] + az * jacobians[i, 1, col]


@njit(cache=True)
def obstacle_points(
    penalty: Array, penalty_gradient: Array, weights: Array, k_obstacle: Array,
    jacobians: Array, at_points: Array, value: Array, gradient: Array,
) -> None:  # fmt: skip
    """``²w = Σ_j Σ_i ½ w_j k¹_i e_ij`` over the body points inside obstacle j (``e < 0``),
    gradient ``Σ ½ w k¹ ∇eᵀ ∂p/∂Q``. ``penalty`` (J, k+1), ``penalty_gradient``
    (J, k+1, 2), ``weights`` (J,), ``k_obstacle`` (k,); ``at_points`` (k, 2) is scratch."""
    k = k_obstacle.shape[0]
    at_points[:, :] = 0.0
    total = 0.0
    for j in range(weights.shape[0]):
        for i in range(k):
            e = penalty[j, i]
            if e < 0.0:
                c = weights[j] * k_obstacle[i]
                total += c * e
                at_points[i, 0] += c * (-0.5 * penalty_gradient[j, i, 0])
                at_points[i, 1] += c * (-0.5 * penalty_gradient[j, i, 1])
    value[0] += 0.5 * total
    _chain(at_points, jacobians, gradient)


@njit(cache=True)
def obstacle_links(
    penalty: Array, penalty_gradient: Array, link_t: Array, weights: Array,
    k_obstacle: Array, jacobians: Array, at_points: Array, value: Array, gradient: Array,
) -> None:  # fmt: skip
    """``³w = Σ_j Σ_i ½ w_j k¹_i e_ij`` over the k−1 body links whose closest point is interior
    (``0 < t < 1``) and inside obstacle j, the gradient shared by the link's ends as
    ``(1 − t, t)``. ``penalty``, ``link_t`` (J, k), ``penalty_gradient`` (J, k, 2),
    ``weights`` (J,), ``k_obstacle`` (k,); ``at_points`` (k, 2) is scratch."""
    k = k_obstacle.shape[0]
    at_points[:, :] = 0.0
    total = 0.0
    for j in range(weights.shape[0]):
        for i in range(k - 1):
            e, t = penalty[j, i], link_t[j, i]
            if e < 0.0 and t > 0.0 and t < 1.0:
                c = weights[j] * k_obstacle[i]
                total += c * e
                al = c * (-0.5 * penalty_gradient[j, i, 0])
                az = c * (-0.5 * penalty_gradient[j, i, 1])
                at_points[i, 0] += al * (1.0 - t)
                at_points[i, 1] += az * (1.0 - t)
                at_points[i + 1, 0] += al * t
                at_points[i + 1, 1] += az * t
    value[0] += 0.5 * total
    _chain(at_points, jacobians, gradient)
