"""Attraction of the body points to the orbital height (paper eq. 11)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.objective import term_kernels
from dvqp.objective.term import Term, per_point, point_gains


class OrbitalLevel:
    """``¹w = −Σ_i ½ k²_i (h_i − h*)²``.

    Parameters
    ----------
    level
        ``h*``, m (finite).
    k_height
        ``k²``, 1/m², scalar or one per body point, >= 0.
    """

    name = "orbital_level"

    def __init__(self, level: float, k_height: ArrayLike = 1.0) -> None:
        if not np.isfinite(level):
            raise ParameterError("orbital_level", "must be finite")
        self.level = float(level)
        self.k_height = point_gains("k_height", k_height)

    def evaluate(self, state: KinematicState) -> Term:
        """Value and ``−Σ_i k²_i (h_i − h*) ∂h_i/∂Q``."""
        dh = state.points[:, 2] - self.level
        kh = per_point("k_height", self.k_height, dh.shape[0])
        value = -0.5 * float(kh @ (dh * dh))
        grad = -(kh * dh) @ state.point_jacobians[:, 2, :]
        return Term(value, grad)

    def kernel(self, plan: StepPlan) -> Kernel:
        """The compiled term (:func:`~dvqp.objective.term_kernels.orbital_level`): adds its
        value and gradient to ``plan.objective_value`` and ``plan.objective_gradient``."""
        kh = np.array(per_point("k_height", self.k_height, plan.k), dtype=np.float64)
        s = plan.state
        args = (s.guarded, s.guarded_jacobians, self.level, kh)
        return Kernel(
            term_kernels.orbital_level, (*args, plan.objective_value, plan.objective_gradient)
        )
