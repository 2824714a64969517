"""The paper's baseline (eq. 18): pseudoinverse plus null-space projection of ``∇w``.

It uses the same tasks and objective as the QP (:func:`dvqp.resolution.qp.step_terms`) and
ignores the limits. With soft tasks the metric becomes ``W + H`` (dense): the step is then
the equality-constrained minimiser of the same cost, solved through its Cholesky factor.

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
from scipy.linalg import cho_factor, cho_solve
from scipy.linalg.lapack import dposv

from dvqp import _validate
from dvqp.errors import ParameterError, SingularConfigurationError
from dvqp.kinematics.state import KinematicState
from dvqp.resolution.qp import StepTerms, step_terms
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Step, check_command

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


def dense_pinv_step(
    jacobian: NDArray[np.float64],
    xdot: NDArray[np.float64],
    gradient: NDArray[np.float64],
    metric: NDArray[np.float64],
) -> NDArray[np.float64]:
    """``Q̇ = M⁻¹g + M⁻¹J̄ᵀ (J̄ M⁻¹ J̄ᵀ)⁻¹ (ẋ − J̄ M⁻¹ g)`` for a dense SPD metric ``M``.

    The minimiser of ``½ Q̇ᵀ M Q̇ − gᵀ Q̇`` subject to ``J̄ Q̇ = ẋ``; with ``M`` diagonal it
    equals :func:`weighted_pinv_step`.

    Raises
    ------
    SingularConfigurationError
        ``M`` is not positive definite or ``J̄ M⁻¹ J̄ᵀ`` is singular.
    """
    try:
        factor = cho_factor(metric, lower=True)
        inv_jt = cho_solve(factor, jacobian.T)  # M⁻¹ J̄ᵀ, (n, m)
        free = cho_solve(factor, gradient)
        gram = cho_factor(jacobian @ inv_jt, lower=True)
    except np.linalg.LinAlgError as exc:
        raise SingularConfigurationError(
            "task Jacobian or soft-task metric is rank deficient"
        ) from exc
    return free + inv_jt @ cho_solve(gram, xdot - jacobian @ free)


class PseudoinverseResolver:
    """The paper's baseline resolver (name ``"pinv"``) on the tasks and objective of a spec.

    Parameters
    ----------
    spec
        Tasks, objective and weights (its limits are not used: the baseline holds none).
    damping
        ``μ >= 0`` of the damped inverse; 0 reproduces eq. 18 and raises at singularities.
    """

    name = "pinv"
    holds_limits = False
    """The baseline holds no limit: runs with it are measured, not verified."""

    def __init__(self, spec: StepSpec, damping: float = 0.0) -> None:
        self.spec = spec
        self.damping = _validate.positive("damping", damping, strict=False)

    def resolve(self, state: KinematicState, command: ArrayLike, dt: float) -> Step:
        """One baseline step (``dt`` only reaches the tasks: the baseline holds no limits)."""
        start = time.perf_counter()
        cmd = check_command(command)
        terms = step_terms(self.spec, state, cmd, dt)
        solving = time.perf_counter()
        qdot = self.solve(terms)
        solved = time.perf_counter()
        error = terms.task_error(qdot)
        elapsed = time.perf_counter() - start
        return Step(qdot, True, "optimal", error, elapsed, solver_time=solved - solving)

    def solve(self, terms: StepTerms) -> NDArray[np.float64]:
        """``Q̇`` (rad/s, shape (n,)) of eq. 18 for evaluated step terms."""
        if terms.soft_hessian is None:
            return weighted_pinv_step(
                terms.A, terms.b, terms.gradient, 1.0 / terms.weights, self.damping
            )
        metric = np.diag(terms.weights) + terms.soft_hessian
        if self.damping > 0.0:
            raise ParameterError("damping", "the damped inverse takes no soft tasks")
        return dense_pinv_step(terms.A, terms.b, terms.gradient, metric)

    def reset(self) -> None:
        """Nothing to forget: the baseline is stateless."""
