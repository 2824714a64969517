"""One term of the objective ``w(Q)``: what every term is, and what the compiled ones share.

dvqp's own terms (:class:`~dvqp.objective.OrbitalLevel`, :class:`~dvqp.objective.ObstaclePoints`,
:class:`~dvqp.objective.ObstacleLinks`) are compiled: each module holds its kernel, which ADDS
the term's value and ``∂w/∂Q`` to the step's (zeroed once per state). A term of your own derives
from :class:`ObjectiveTerm` and implements :meth:`ObjectiveTerm.evaluate` in NumPy: a run
adds it after the compiled terms, on the same state.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import Kernel, StepPlan
from dvqp.workspace.wiring import StepWiring
from solvers.jit import njit

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Term:
    """A value of ``w`` (or of one of its terms) and its gradient ``∂w/∂Q``, shape (n,)."""

    value: float
    gradient: NDArray[np.float64]


class ObjectiveTerm:
    """A term of ``w(Q)``, which the resolution step maximises in the task's null space.

    Attributes
    ----------
    name : str
        A label for reports.
    """

    name: str = "term"

    def evaluate(self, state: KinematicState) -> Term:
        """Value and gradient ``∂w/∂Q`` (shape (n,)) of the term at ``state``: implement it for
        a term of your own (dvqp's terms return what their kernels add)."""
        raise NotImplementedError(f"{type(self).__name__} has no evaluate(state)")

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """Optionally, the term as a compiled kernel ADDING its value and gradient to
        ``plan.objective_value`` (1,) and ``plan.objective_gradient`` (n,) at ``plan.state``.
        None (the default): :meth:`evaluate` is used."""
        return None

    @property
    def measured(self) -> Sequence[Any]:
        """The obstacles whose distances the step must measure for this term (none)."""
        return ()

    def join(self, step: StepWiring) -> None:
        """Join the run's step: a term of your own through the run's hooks (its
        :meth:`kernel`, else :meth:`evaluate`); dvqp's own terms write their coefficients into
        the compiled objective's tables instead."""
        step.hooks.term(self)


def point_gains(name: str, value: ArrayLike) -> Array:
    """A per-body-point gain: a scalar or a vector (one per point), finite and >= 0."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim > 1:
        raise ShapeError(name, (-1,), arr.shape)
    if not np.isfinite(arr).all():
        raise ParameterError(name, "must be finite")
    if np.any(arr < 0):
        raise ParameterError(name, "must be >= 0")
    return _validate.readonly(arr.copy())


def per_point(name: str, gains: Array, k: int) -> Array:
    """``gains`` for k body points, shape (k,) (a scalar is repeated)."""
    return _validate.broadcast(name, gains, k)


@njit(inline="always")
def pull_points(at_points: Array, jacobians: Array, gradient: Array) -> None:
    """``gradient −= Σ_i at_points[i] · ∂[l, z, h]_i/∂Q`` over the k body points
    (``at_points`` (k, 3), ``jacobians`` the guarded points' (k+1, 3, n); the h part is 0
    but for obstacles with a height)."""
    for i in range(at_points.shape[0]):
        al, az, ah = at_points[i, 0], at_points[i, 1], at_points[i, 2]
        if al == 0.0 and az == 0.0 and ah == 0.0:
            continue
        jac = jacobians[i]
        for col in range(gradient.shape[0]):
            gradient[col] -= al * jac[0, col] + az * jac[1, col] + ah * jac[2, col]
