"""Dense convex QP backends behind one interface, with solutions checked by residuals.

>>> from solvers import Problem, make_backend
>>> backend = make_backend("daqp")
>>> x = backend.solve(Problem(P, q, A=A, b=b)).require()  # doctest: +SKIP
"""

from . import daqp_c  # noqa: F401  (DAQP's C calls: its kernel's cache listed with the rest)
from .exceptions import ProblemShapeError, SolverError, UnknownBackendError
from .problem import Problem
from .protocol import Backend
from .refusal import REFUSALS
from .registry import (
    BackendInfo,
    available_backends,
    backend_versions,
    describe_backends,
    make_backend,
)
from .residuals import Residuals, residuals
from .solution import Solution, SolverFailure
from .stateful import RawResult, StatefulBackend

__all__ = [
    "REFUSALS",
    "Backend",
    "BackendInfo",
    "Problem",
    "ProblemShapeError",
    "RawResult",
    "Residuals",
    "Solution",
    "SolverError",
    "SolverFailure",
    "StatefulBackend",
    "UnknownBackendError",
    "available_backends",
    "backend_versions",
    "describe_backends",
    "make_backend",
    "residuals",
]
