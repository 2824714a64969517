"""Exceptions raised by the ``solvers`` package."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .solution import Solution


class SolverError(Exception):
    """Base class of every error raised by ``solvers``."""


class ProblemShapeError(SolverError, ValueError):
    """A :class:`~solvers.Problem` was built from inconsistent or invalid data.

    The message names the offending field first, e.g.
    ``G: expected shape (p, 13), got (4, 12)``.
    """


class UnknownBackendError(SolverError, ValueError):
    """The requested backend name is not installed or does not exist.

    Attributes
    ----------
    name : str
        The name that was asked for.
    installed : list of str
        Every backend name :func:`~solvers.make_backend` accepts here.
    """

    def __init__(self, name: str, installed: list[str]) -> None:
        self.name = name
        self.installed = list(installed)
        listed = ", ".join(self.installed) if self.installed else "none"
        super().__init__(
            f"unknown QP backend {name!r}; installed: {listed}; "
            "more with: pip install 'dvqp[solvers]'"
        )


class SolverFailure(SolverError):
    """Raised by :meth:`Solution.require` when no acceptable solution was found.

    Attributes
    ----------
    solution : Solution
        The failed solution, with its status, residuals and message.
    """

    def __init__(self, solution: Solution) -> None:
        self.solution = solution
        super().__init__(solution.message or f"{solution.backend}: no solution found")
