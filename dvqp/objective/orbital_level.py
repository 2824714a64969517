"""Attraction of the body points to the orbital height (paper eq. 11)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.objective.term import Array, ObjectiveTerm, Term, per_point, point_gains
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class OrbitalLevel(ObjectiveTerm):
    """``¹w = −Σ_i ½ k²_i (h_i − h*)²`` (compiled: :func:`orbital_level`).

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
        """What :func:`orbital_level` adds at ``state``."""
        value, gradient = np.zeros(1), np.zeros(state.n)
        gains = per_point("k_height", self.k_height, state.k)
        orbital_level(state.guarded, state.guarded_jacobians, self.level, gains, value, gradient)
        return Term(float(value[0]), gradient)

    def join(self, step: StepWiring) -> None:
        """A row of the compiled objective's levels (``h*``, ``k²`` per body point)."""
        if overrides(self, OrbitalLevel, "evaluate", "kernel"):
            return super().join(step)
        step.levels.append(self.level)
        step.k_height.append(per_point("k_height", self.k_height, step.plan.k))
        return None


@njit(separate=True)
def orbital_level(
    guarded: Array, jacobians: Array, level: float, k_height: Array, value: Array, gradient: Array
) -> None:
    """Add ``−Σ_i ½ k²_i (h_i − h*)²`` to ``value`` (1,) and ``−Σ_i k²_i (h_i − h*) ∂h_i/∂Q``
    to ``gradient`` (n,), over the k body points (``k_height`` (k,), 1/m²; ``level`` h*, m;
    ``guarded`` (k+1, 3) and ``jacobians`` (k+1, 3, n) the guarded points')."""
    total = 0.0
    for i in range(k_height.shape[0]):
        dh = guarded[i, 2] - level
        total += k_height[i] * (dh * dh)
        c = k_height[i] * dh
        for col in range(gradient.shape[0]):
            gradient[col] -= c * jacobians[i, 2, col]
    value[0] += -0.5 * total
