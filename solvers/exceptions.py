"""Exceptions raised by the ``solvers`` package.

Every one is a :class:`SolverError`; :class:`~solvers.SolverFailure`, which carries a
:class:`~solvers.Solution`, is defined next to it in :mod:`solvers.solution`.
"""

from __future__ import annotations


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
