"""Dense convex QP backends behind one interface, with solutions checked by residuals.

>>> from solvers import Problem, make_backend
>>> backend = make_backend("daqp")
>>> x = backend.solve(Problem(P, q, A=A, b=b)).require()  # doctest: +SKIP
"""

from .exceptions import ProblemShapeError, SolverError, SolverFailure, UnknownBackendError
from .problem import Problem
from .protocol import Backend
from .registry import available_backends, backend_versions, make_backend
from .residuals import Residuals, residuals
from .solution import Solution

__all__ = [
    "Backend",
    "Problem",
    "ProblemShapeError",
    "Residuals",
    "Solution",
    "SolverError",
    "SolverFailure",
    "UnknownBackendError",
    "available_backends",
    "backend_versions",
    "make_backend",
    "residuals",
]
