"""The objective ``w(Q)``: a sum of terms, maximised in the task's null space with gain λ.

The paper's objective (eq. 10–17) is :meth:`Objective.paper`: the orbital level, the
obstacle points and the obstacle links. Terms of your own (:class:`ObjectiveTerm` with a NumPy
``evaluate``) can be added.
"""

from __future__ import annotations

from collections.abc import Sequence

from numpy.typing import ArrayLike

from dvqp import _validate
from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.objective.obstacle_links import ObstacleLinks
from dvqp.objective.obstacle_points import ObstaclePoints
from dvqp.objective.orbital_level import OrbitalLevel
from dvqp.objective.term import ObjectiveTerm


class Objective:
    """``w = Σ terms`` and the gain ``λ`` that scales ``∇w`` in the step.

    Parameters
    ----------
    terms
        The terms (:class:`ObjectiveTerm`).
    gain
        ``λ`` (>= 0).
    """

    def __init__(self, terms: Sequence[ObjectiveTerm] = (), gain: float = 1.0) -> None:
        self.terms = tuple(terms)
        for i, term in enumerate(self.terms):
            if not isinstance(term, ObjectiveTerm):
                raise ParameterError(f"terms[{i}]", "must be a dvqp.ObjectiveTerm")
        self.gain = _validate.positive("gain", gain, strict=False)

    @classmethod
    def paper(
        cls,
        orbital_level: float,
        obstacles: ObstacleSet,
        *,
        k_height: ArrayLike = 1.0,
        k_obstacle: ArrayLike = 1.0,
        gain: float = 1.0,
    ) -> Objective:
        """The paper's three terms: orbital level, obstacle points, obstacle links."""
        terms = (
            OrbitalLevel(orbital_level, k_height),
            ObstaclePoints(obstacles, k_obstacle),
            ObstacleLinks(obstacles, k_obstacle),
        )
        return cls(terms, gain)

    def __repr__(self) -> str:
        return f"Objective({[t.name for t in self.terms]!r}, gain={self.gain!r})"
