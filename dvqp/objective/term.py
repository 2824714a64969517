"""One term of the objective ``w(Q)``: its value and gradient at a state."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, ShapeError
from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Term:
    """A value of ``w`` (or of one of its terms) and its gradient ``∂w/∂Q``, shape (n,)."""

    value: float
    gradient: NDArray[np.float64]


@runtime_checkable
class ObjectiveTerm(Protocol):
    """A term of ``w(Q)``, which the resolution step maximises in the task's null space.

    Implement ``name`` and :meth:`evaluate`; :class:`~dvqp.objective.Objective` adds the
    terms up.

    Optionally, for the compiled step, a term may also have ``kernel(plan) ->
    Kernel | None`` (not a member of this protocol): a :class:`~dvqp.compiled.plan.Kernel`
    that ADDS the term's value and gradient to ``plan.objective_value`` (1,) and
    ``plan.objective_gradient`` (n,) at the state in ``plan.state``, with the same math as
    :meth:`evaluate`. A term without it (or returning None) makes the run take the reference
    (uncompiled) path.
    """

    name: str

    def evaluate(self, state: KinematicState) -> Term:
        """Value and gradient ``∂w/∂Q`` (shape (n,)) of the term at ``state``."""
        ...


def point_gains(name: str, value: ArrayLike) -> NDArray[np.float64]:
    """A per-body-point gain: a scalar or a vector (one per point), finite and >= 0."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim > 1:
        raise ShapeError(name, (-1,), arr.shape)
    if not np.isfinite(arr).all():
        raise ParameterError(name, "must be finite")
    if np.any(arr < 0):
        raise ParameterError(name, "must be >= 0")
    return _validate.readonly(arr.copy())


def per_point(name: str, gains: NDArray[np.float64], k: int) -> NDArray[np.float64]:
    """``gains`` for k body points, shape (k,) (a scalar is repeated)."""
    if gains.ndim == 0:
        return np.full(k, float(gains))
    if gains.shape[0] != k:
        raise ShapeError(name, (k,), gains.shape)
    return gains
