"""Backend names -> factories, built from whatever solver packages import here.

Plain names are the best adapter for a solver: the direct stateful adapters
for ``osqp``, ``clarabel``, ``daqp`` and ``proxqp``, the generic ``qpsolvers``
path for every other solver ``qpsolvers`` finds (``quadprog``, ``piqp``,
``highs``, ...). ``qpsolvers:NAME`` forces the generic path for any solver
``qpsolvers`` has installed. :func:`describe_backends` says which package
(and version) is behind each name.
"""

from __future__ import annotations

import functools
import importlib
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata
from typing import Any

import numpy as np

from .c_output import c_output_captured
from .exceptions import SolverError, UnknownBackendError
from .problem import Problem
from .protocol import Backend

QPSOLVERS_PREFIX = "qpsolvers:"

#: Version shown for a distribution whose metadata is not found.
UNKNOWN = "?"

#: Direct adapters: backend name -> (module, class name).
DIRECT: dict[str, tuple[str, str]] = {
    "clarabel": ("clarabel_", "ClarabelBackend"),
    "daqp": ("daqp_", "DaqpBackend"),
    "osqp": ("osqp_", "OsqpBackend"),
    "proxqp": ("proxqp_", "ProxqpBackend"),
}

#: Distribution name of a solver when it differs from the solver name.
DISTRIBUTIONS: dict[str, str] = {
    "highs": "highspy",
    "proxqp": "proxsuite",
    "gurobi": "gurobipy",
    "hpipm": "hpipm_python",
    "jaxopt_osqp": "jaxopt",
    "qpswift": "qpSWIFT",
    "qpoases": "qpoases",
}

Factory = Callable[..., Backend]


def _qpsolvers_names() -> list[str]:
    try:
        qpsolvers = importlib.import_module("qpsolvers")
    except ImportError:
        return []
    return sorted(qpsolvers.available_solvers)


def _generic(solver: str, name: str) -> Factory:
    def factory(**options: Any) -> Backend:
        from .qpsolvers_ import QpsolversBackend

        return QpsolversBackend(solver, name=name, **options)

    return factory


@functools.cache
def _direct_factories() -> dict[str, Factory]:
    """The direct adapters whose solver package imports here."""
    factories: dict[str, Factory] = {}
    for name, (module_name, class_name) in DIRECT.items():
        try:
            module = importlib.import_module(f".{module_name}", __package__)
        except ImportError:
            continue
        factories[name] = getattr(module, class_name)
    return factories


@functools.cache
def _factories() -> dict[str, Factory]:
    factories = dict(_direct_factories())
    for solver in _qpsolvers_names():
        factories.setdefault(solver, _generic(solver, solver))
        factories[QPSOLVERS_PREFIX + solver] = _generic(solver, QPSOLVERS_PREFIX + solver)
    return factories


def available_backends() -> list[str]:
    """Names :func:`make_backend` accepts here: plain names first, then ``qpsolvers:*``.

    Returns
    -------
    list of str
        Sorted, e.g. ``['clarabel', 'daqp', ..., 'qpsolvers:clarabel', ...]``.
    """
    names = list(_factories())
    return sorted(names, key=lambda name: (name.startswith(QPSOLVERS_PREFIX), name))


def make_backend(name: str, **options: Any) -> Backend:
    """Create a fresh backend instance (no state shared with earlier instances).

    Parameters
    ----------
    name : str
        One of :func:`available_backends`.
    **options
        ``tolerance=``, ``solver_defaults=`` (start from the solver's factory defaults, not
        the adapter's own: :mod:`solvers.tiers`) and solver settings, forwarded to the
        adapter.

    Returns
    -------
    Backend
        A new adapter.

    Raises
    ------
    UnknownBackendError
        If ``name`` is not installed; carries ``.name`` and ``.installed``.
    """
    factory = _factories().get(name)
    if factory is None:
        raise UnknownBackendError(name, available_backends())
    backend = factory(**options)
    settings = sorted(set(options) - {"tolerance", "solver_defaults"})
    if settings:
        _try_settings(backend, settings)
    return backend


def _try_settings(backend: Backend, names: list[str]) -> None:
    """Solve a one-variable problem with the settings given: a solver that refuses one (a
    wrong type, a name its wrapper does not read, a value out of its range) raises
    :class:`SolverError` here, not in the middle of a run. The reason is the whole message,
    on one line, after what the solver's C library printed (OSQP prints its reason, ``eps_abs
    must be nonnegative``, and raises ``OSQPException: 2``); nothing reaches the terminal."""
    tiny = Problem(np.eye(1), np.zeros(1), G=-np.eye(1), h=-np.ones(1))  # x >= 1, active
    printed: list[str] = []
    try:
        with warnings.catch_warnings(), c_output_captured(printed):
            warnings.simplefilter("ignore")
            solution = backend.solve(tiny)
    except SolverError as exc:
        reason = str(exc)
    else:
        backend.reset()
        if solution.status != "exception":
            return
        reason = solution.message
    reason = " ".join(reason.split())
    if printed:
        reason = f"{'; '.join(printed)} ({reason})"
    raise SolverError(f"{backend.name}: settings {', '.join(names)} refused: {reason}")


def backend_versions() -> dict[str, str]:
    """Installed versions of ``qpsolvers`` and every solver package in use.

    Returns
    -------
    dict of str to str
        Distribution name -> version, e.g. ``{'osqp': '1.1.3', ...}``.
    """
    solvers = {name.removeprefix(QPSOLVERS_PREFIX) for name in _factories()}
    distributions = {"qpsolvers", *(DISTRIBUTIONS.get(s, s) for s in solvers)}
    versions = {dist: _version(dist) for dist in sorted(distributions)}
    return {dist: version for dist, version in versions.items() if version != UNKNOWN}


@dataclass(frozen=True)
class BackendInfo:
    """The package behind one backend name.

    Attributes
    ----------
    name : str
        The name :func:`make_backend` accepts, e.g. ``'daqp'`` or ``'qpsolvers:quadprog'``.
    distribution : str
        The Python distribution of the solver, e.g. ``'proxsuite'`` for ``proxqp``.
    version : str
        Its installed version, ``'?'`` if unknown.
    note : str
        How the solver is reached: ``'via qpsolvers 4.13.0'`` on the generic path, ``''``
        for a direct adapter.
    """

    name: str
    distribution: str
    version: str
    note: str


def describe_backends() -> list[BackendInfo]:
    """One :class:`BackendInfo` per name of :func:`available_backends`, in that order.

    Returns
    -------
    list of BackendInfo
        E.g. ``BackendInfo('highs', 'highspy', '1.16.0', 'via qpsolvers 4.13.0')``.
    """
    direct = _direct_factories()
    via = f"via qpsolvers {_version('qpsolvers')}"
    infos = []
    for name in available_backends():
        solver = name.removeprefix(QPSOLVERS_PREFIX)
        dist = DISTRIBUTIONS.get(solver, solver)
        infos.append(BackendInfo(name, dist, _version(dist), "" if name in direct else via))
    return infos


def _version(distribution: str) -> str:
    """The installed version of a distribution, :data:`UNKNOWN` if it is not found."""
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return UNKNOWN
