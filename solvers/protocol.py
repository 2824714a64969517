"""The one interface every QP backend implements."""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .problem import Problem
from .solution import Solution


@runtime_checkable
class Backend(Protocol):
    """A QP solver adapter.

    Attributes
    ----------
    name : str
        Registry name, e.g. ``'osqp'`` or ``'qpsolvers:quadprog'``.
    tolerance : float
        Absolute tolerance on the primal residuals used to accept a solution;
        also the accuracy on ``x`` the backend is configured to reach.

    Notes
    -----
    ``solve`` never raises because a solver failed: it returns a
    :class:`~solvers.Solution` with ``found=False`` and a ``message``. Errors
    in the adapter itself (programming errors) raise :class:`~solvers.SolverError`.
    Stateful backends warm-start from their previous solve while the problem
    structure is unchanged; ``reset`` forgets that state.
    """

    name: str
    tolerance: float

    def solve(self, problem: Problem, initvals: np.ndarray | None = None) -> Solution:
        """Solve ``problem``.

        Parameters
        ----------
        problem : Problem
            The QP.
        initvals : ndarray, shape (n,), optional
            Primal guess; used where the solver supports it.

        Returns
        -------
        Solution
            Checked by :meth:`Solution.checked`.
        """
        ...

    def reset(self) -> None:
        """Drop any warm-start state; the next solve starts cold."""
        ...
