"""The paper's baseline (eq. 18): pseudoinverse plus null-space projection of ``∇w``.

Weighted least-norm form with a positive diagonal ``W`` (``W = I`` gives eq. 18)::

    J̄_W⁺ = W⁻¹ J̄ᵀ (J̄ W⁻¹ J̄ᵀ + μ² I)⁻¹
    Q̇    = J̄_W⁺ ẋ + (I − J̄_W⁺ J̄) W⁻¹ g,        g = λ ∂w/∂Q

which is ``W⁻¹ g + J̄_W⁺ (ẋ − J̄ W⁻¹ g)``. With ``μ = 0`` this is exactly the minimiser of
``½ Q̇ᵀ W Q̇ − gᵀ Q̇`` subject to ``J̄ Q̇ = ẋ``. ``μ > 0`` is the damped (singularity-robust)
inverse: finite everywhere, at the price of a task error near singularities.
"""

from __future__ import annotations

import math
import time

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg.lapack import dposv

from dvqp import _validate
from dvqp.errors import ParameterError, SingularConfigurationError
from dvqp.resolution.step import Step, step_inputs, task_error
from dvqp.kinematics.state import KinematicState

SINGULAR_RCOND = 1e-10
"""Smallest ratio of Cholesky pivots of ``J̄ W⁻¹ J̄ᵀ`` (about its reciprocal condition number)
below which the undamped inverse is refused."""


def weighted_pinv_step(
    jacobian: NDArray[np.float64],
    xdot: NDArray[np.float64],
    gradient: NDArray[np.float64],
    inv_weights: NDArray[np.float64],
    damping: float = 0.0,
) -> NDArray[np.float64]:
    """``Q̇ = W⁻¹g + J̄_W⁺ (ẋ − J̄ W⁻¹ g)`` for a (m, n) Jacobian.

    Parameters
    ----------
    jacobian
        ``J̄``, shape (m, n).
    xdot
        Task velocity, shape (m,).
    gradient
        ``g``, shape (n,).
    inv_weights
        Diagonal of ``W⁻¹``, shape (n,), > 0.
    damping
        ``μ`` (units of the task), >= 0.

    Raises
    ------
    SingularConfigurationError
        ``μ = 0`` and ``J̄ W⁻¹ J̄ᵀ`` is singular (rank-deficient task).
    """
    jw = jacobian * inv_weights  # J W⁻¹, (m, n)
    gram = jw @ jacobian.T
    if damping > 0.0:
        gram = gram + damping * damping * np.eye(gram.shape[0])
    free = inv_weights * gradient
    # Cholesky solve of the SPD Gram matrix (LAPACK dposv: a few µs, unlike np.linalg.solve).
    factor, lam, info = dposv(gram, xdot - jacobian @ free, lower=1)
    pivots = np.diagonal(factor) ** 2
    if info != 0 or not math.isfinite(float(pivots.sum() + lam.sum())):
        if not math.isfinite(float(gram.sum() + xdot.sum() + gradient.sum())):
            raise ParameterError("inputs", "jacobian, xdot and gradient must be finite")
        raise SingularConfigurationError(
            "task Jacobian is rank deficient (J W^-1 J^T is not positive definite); "
            "use a damped inverse"
        )
    if damping == 0.0 and pivots.min() <= SINGULAR_RCOND * pivots.max():
        raise SingularConfigurationError(
            f"task Jacobian is nearly rank deficient (Cholesky pivots from {pivots.min():.3g} "
            f"to {pivots.max():.3g}); use a damped inverse"
        )
    return free + jw.T @ lam


class PseudoinverseResolver:
    """The paper's baseline resolver (name ``"pinv"``).

    Parameters
    ----------
    weights
        Diagonal of ``W`` (> 0), scalar or shape (n,). Default: identity.
    damping
        ``μ >= 0`` of the damped inverse; 0 reproduces eq. 18 and raises at singularities.
    """

    name = "pinv"

    def __init__(self, weights: ArrayLike | None = None, damping: float = 0.0) -> None:
        self._weights = None if weights is None else np.asarray(weights, dtype=float)
        if self._weights is not None and (
            not np.all(np.isfinite(self._weights)) or np.any(self._weights <= 0)
        ):
            raise ParameterError("weights", "must be finite and > 0")
        self.damping = _validate.positive("damping", damping, strict=False)

    def inverse_weights(self, n: int) -> NDArray[np.float64]:
        """Diagonal of ``W⁻¹`` for n joints, shape (n,)."""
        if self._weights is None:
            return np.ones(n)
        return 1.0 / _validate.broadcast("weights", self._weights, n)

    def resolve(
        self,
        state: KinematicState,
        gradient: NDArray[np.float64],
        xdot: NDArray[np.float64],
        dt: float,
    ) -> Step:
        """One baseline step (``dt`` is unused: the baseline holds no limits)."""
        start = time.perf_counter()
        g, xd = step_inputs(state, gradient, xdot)
        inv_w = self.inverse_weights(state.n)
        qdot = weighted_pinv_step(state.tool_jacobian, xd, g, inv_w, self.damping)
        elapsed = time.perf_counter() - start
        error = task_error(state, qdot, xd)
        return Step(qdot=qdot, success=True, status="optimal", task_error=error, solve_time=elapsed)

    def reset(self) -> None:
        """Nothing to forget: the baseline is stateless."""
