"""The interface every redundancy resolver implements, and the result of one step."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.kinematics.state import KinematicState


@dataclass(frozen=True)
class Step:
    """The joint velocity chosen for one step and how it was obtained.

    Attributes
    ----------
    qdot : ndarray, shape (n,)
        Joint velocity, rad/s (zeros when ``success`` is False).
    success : bool
        The step satisfies every hard limit of the resolver (checked, not the solver's word).
    status : str
        ``"optimal"``, ``"relaxed"`` (task slack used), or the failure reason.
    task_error : float
        ``‖J̄·Q̇ − ẋ‖∞`` (m/s or rad/s) of the tool DV task.
    solve_time : float
        Wall time of the resolution (QP assembly + solve + check, or the pseudoinverse), s.
    iterations : int or None
        Solver iterations, where the backend reports them.
    """

    qdot: NDArray[np.float64]
    success: bool
    status: str
    task_error: float
    solve_time: float
    iterations: int | None = None


def step_inputs(
    state: KinematicState, gradient: NDArray[np.float64], xdot: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Check a resolver's inputs: ``gradient`` (n,) and ``xdot`` (m,), finite.

    Raises
    ------
    ShapeError, ParameterError
        Wrong size or not finite.
    """
    g = _validate.vector("gradient", gradient, state.n)
    xd = _validate.vector("xdot", xdot, state.tool_jacobian.shape[0])
    return g, xd


def task_error(
    state: KinematicState, qdot: NDArray[np.float64], xdot: NDArray[np.float64]
) -> float:
    """``‖J̄·Q̇ − ẋ‖∞`` of the tool's DV task."""
    return float(np.abs(state.tool_jacobian @ qdot - xdot).max())


class Resolver(Protocol):
    """Chooses ``Q̇`` that tracks the tool's DV velocity and follows ``λ∇w`` in the rest."""

    name: str

    def resolve(
        self,
        state: KinematicState,
        gradient: NDArray[np.float64],
        xdot: NDArray[np.float64],
        dt: float,
    ) -> Step:
        """One step.

        Parameters
        ----------
        state
            Kinematics at the current configuration.
        gradient
            ``λ·∂w/∂Q``, shape (n,).
        xdot
            Commanded tool DV velocity ``[l̇, ż, ḣ, α̇]`` (m/s, m/s, m/s, rad/s), shape (4,).
        dt
            Step length, s (used by position limits and dampers).
        """
        ...

    def reset(self) -> None:
        """Forget any state carried between steps (warm starts)."""
        ...
