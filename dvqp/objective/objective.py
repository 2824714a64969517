"""The objective ``w(Q)``: a sum of terms, maximised in the task's null space with gain λ.

The paper's objective (eq. 10–17) is :meth:`Objective.paper`: the orbital level, the
obstacle points and the obstacle links. Any object with ``name`` and ``evaluate(state)``
(:class:`~dvqp.objective.term.ObjectiveTerm`) can be added.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp import _validate
from dvqp.compiled import ownership
from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.state import KinematicState
from dvqp.objective.obstacle_links import ObstacleLinks
from dvqp.objective.obstacle_points import ObstaclePoints
from dvqp.objective.orbital_level import OrbitalLevel
from dvqp.objective.term import ObjectiveTerm, Term


class Objective:
    """``w = Σ terms`` and the gain ``λ`` that scales ``∇w`` in the step.

    Parameters
    ----------
    terms
        The terms, each with ``evaluate(state) -> Term``.
    gain
        ``λ`` (>= 0).
    """

    def __init__(self, terms: Sequence[ObjectiveTerm] = (), gain: float = 1.0) -> None:
        self.terms = tuple(terms)
        for i, term in enumerate(self.terms):
            if not callable(getattr(term, "evaluate", None)):
                raise ParameterError(f"terms[{i}]", "must have an evaluate(state) method")
        self.gain = _validate.positive("gain", gain, strict=False)

    @classmethod
    def paper(
        cls, orbital_level: float, obstacles: ObstacleSet, *, k_height: ArrayLike = 1.0,
        k_obstacle: ArrayLike = 1.0, gain: float = 1.0,
    ) -> Objective:  # fmt: skip
        """The paper's three terms: orbital level, obstacle points, obstacle links."""
        return cls(
            (
                OrbitalLevel(orbital_level, k_height),
                ObstaclePoints(obstacles, k_obstacle),
                ObstacleLinks(obstacles, k_obstacle),
            ),
            gain,
        )

    def evaluate(self, state: KinematicState) -> Term:
        """``w(Q)`` and ``∂w/∂Q`` (shape (n,)), computed once per state and cached on it."""
        found = state.cache.get(self)
        if found is not None:
            return found  # type: ignore[no-any-return]
        terms = [term.evaluate(state) for term in self.terms]
        if not terms:
            total = Term(0.0, np.zeros(state.n))
        else:
            gradient = terms[0].gradient
            for term in terms[1:]:
                gradient = gradient + term.gradient
            total = Term(sum(t.value for t in terms), gradient)
        state.cache[self] = total
        return total

    def kernels(self, plan: StepPlan) -> list[Kernel] | None:
        """The terms' compiled kernels, in order, or None if a term has none.

        Each kernel ADDS its term's value and ``∂w/∂Q`` to ``plan.objective_value`` (1,) and
        ``plan.objective_gradient`` (n,), which the caller zeroes once per state first; the
        gain ``λ`` is not applied (the caller scales the gradient by :attr:`gain`). With no
        term the list is empty (``w = 0``). None if a term has no ``kernel(plan)`` method or
        its ``kernel`` returns None, or a subclass overrides ``evaluate`` but not ``kernel``
        (:func:`dvqp.compiled.ownership.own_kernel`): the run then takes the reference path.
        """
        kernels = []
        for term in self.terms:
            ok, kernel = ownership.build(term, "kernel", plan)
            if not ok or kernel is None:
                return None
            kernels.append(kernel)
        return kernels

    def scaled_gradient(self, state: KinematicState) -> NDArray[np.float64]:
        """``g = λ ∂w/∂Q``, shape (n,): what the resolution step follows."""
        return self.gain * self.evaluate(state).gradient

    def __repr__(self) -> str:
        return f"Objective({[t.name for t in self.terms]!r}, gain={self.gain!r})"
