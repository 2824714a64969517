"""Constants and small builders shared by the tests (robot fixtures are built in code)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from dvqp import (
    KinematicState,
    Objective,
    ObjectiveTerm,
    Obstacle,
    ObstacleSet,
    PseudoinverseResolver,
    StepSpec,
    Term,
    ToolTask,
)

PIPE_RADIUS = 0.254
ORBITAL_LEVEL = 0.08
LINK_LENGTHS = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
Q0 = [
    1.5708,
    -0.048,
    0.068,
    0.026,
    0.08,
    0.032,
    0.088,
    -0.078,
    -0.088,
    0.003,
    -0.434,
    0.116,
    -0.278,
]


def random_configurations(count: int, seed: int = 0, spread: float = 0.6) -> np.ndarray:
    """Configurations around the start configuration (rad), shape (count, 13)."""
    rng = np.random.default_rng(seed)
    return np.array(Q0) + rng.uniform(-spread, spread, size=(count, 13))


def objective_with(obstacles: list[Obstacle], **kw: object) -> Objective:
    """The paper's objective (h* = 0.08 m) with the given obstacles."""
    return Objective.paper(ORBITAL_LEVEL, ObstacleSet(obstacles), **kw)  # type: ignore[arg-type]


def central_difference(f, x: np.ndarray, eps: float = 1e-6, wrap=None) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Central finite-difference Jacobian of ``f`` at ``x``, shape f(x).shape + (len(x),).

    ``wrap`` (optional) is applied to each difference ``f(x+) − f(x−)`` (for l and α).
    """
    cols = []
    for i in range(x.shape[0]):
        e = np.zeros_like(x)
        e[i] = eps
        d = np.asarray(f(x + e)) - np.asarray(f(x - e))
        if wrap is not None:
            d = wrap(d)
        cols.append(d / (2 * eps))
    return np.stack(cols, axis=-1)


class ConstantGradient(ObjectiveTerm):
    """An objective term with value 0 and a fixed gradient (to feed a resolver a given g); a
    term of your own, so a run adds it through its NumPy ``evaluate``."""

    name = "constant"

    def __init__(self, gradient: ArrayLike) -> None:
        self.gradient = np.asarray(gradient, dtype=float)

    def evaluate(self, state: KinematicState) -> Term:
        return Term(0.0, self.gradient)


def spec_with(gradient: ArrayLike, weights: ArrayLike = 1.0, limits: tuple = ()) -> StepSpec:  # type: ignore[type-arg]
    """The tool's DV task, ``g = gradient`` (λ = 1), the given weights and limits."""
    objective = Objective((ConstantGradient(gradient),), gain=1.0)
    return StepSpec((ToolTask(),), objective, limits, weights)


def baseline(objective: Objective) -> PseudoinverseResolver:
    """The paper's baseline on the tool's DV task and ``objective``."""
    return PseudoinverseResolver(StepSpec((ToolTask(),), objective))


def obstacles_of(objective: Objective) -> ObstacleSet:
    """The obstacle set of an objective made by :func:`objective_with`."""
    return objective.terms[1].obstacles  # type: ignore[attr-defined, no-any-return]
