"""What every resolver is, and the result of one step."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp.resolution.spec import StepSpec
from dvqp.workspace import QPBuffers


class Step(NamedTuple):
    """The joint velocity chosen for one step and how it was obtained (immutable).

    Attributes
    ----------
    qdot : ndarray, shape (n,)
        Joint velocity, rad/s (zeros when ``success`` is False).
    success : bool
        The step satisfies every hard limit of the resolver (checked, not the solver's word).
    status : str
        ``"optimal"``, ``"slowed"`` (a path's progress slowed), ``"relaxed"`` (task slack
        used), ``"braking"``, or the failure reason.
    task_error : float
        ``‖A·Q̇ − b‖∞`` of the hard tasks (m/s or rad/s; ``inf`` for a failed step).
    solve_time : float
        Wall time of the resolution (QP assembly + solve + check, or the pseudoinverse), s.
    iterations : int or None
        Solver iterations, where the backend reports them.
    solver_time : float
        Of ``solve_time``, the time inside the QP backend's calls (data update and solve), s;
        for the baseline, its linear algebra.
    rate : float
        The fraction of the commanded progress along a path the step made, in [0, 1]: below 1
        when a time-scaled step slowed (0 for a failed one); 1 without time scaling.
    level_error : ndarray of shape (L,) or None
        Each level's ``‖A_k Q̇ − b_k‖∞`` (levels by priority, 1 first; ``inf`` for a failed
        step); None: one level, whose error is ``task_error``.
    """

    qdot: NDArray[np.float64]
    success: bool
    status: str
    task_error: float
    solve_time: float
    iterations: int | None = None
    solver_time: float = 0.0
    rate: float = 1.0
    level_error: NDArray[np.float64] | None = None


class Resolver:
    """Chooses ``Q̇`` for the tasks of a :class:`StepSpec`, following ``λ∇w`` in the rest.

    Attributes
    ----------
    name : str
        Its registry name (``"pinv"``, ``"daqp"``, ...).
    spec : StepSpec
        What a step is made of.
    holds_limits : bool
        True if it keeps ``spec.limits`` (then runs are verified against them).
    """

    name: str = "resolver"
    holds_limits: bool = True

    def __init__(self, spec: StepSpec) -> None:
        self.spec = spec

    def solver(
        self,
        qp: QPBuffers,
        task_weight: float,
        levels: NDArray[np.int64],
        row_weights: NDArray[np.float64],
    ) -> Any:
        """The :class:`~dvqp.resolution.qp.QPSolver` a step of this resolver calls on the
        step's QP ``qp`` (the tasks' weight ``ρ``, their ``levels`` (L + 1,) and
        ``row_weights`` (m,)), or None: the step is computed in the step's compiled code (the
        baseline, :meth:`baseline_damping`)."""
        return None

    def baseline_damping(self) -> float | None:
        """The damping ``μ >= 0`` of the baseline's nested inverse if this resolver's step is
        the baseline's (eq. 18, in the step's compiled code), else None."""
        return None
