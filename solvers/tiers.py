"""Settings tiers: solvers' own tight ``default``, and qpbenchmark's four.

A tier is a set of solver settings plus the tolerance of :mod:`solvers`' own check of every
answer (:attr:`Backend.tolerance <solvers.Backend.tolerance>`), so that a solver is asked for
the accuracy its answer is then held to:

- ``default``: **this package's** defaults (each backend's ``default_settings``, tuned so that
  every backend reaches ~1e-7 on ``x`` on dvqp-sized problems, OSQP polishing; the check's
  tolerance 1e-6). Tighter than the solvers' factory defaults and than qpbenchmark's
  ``default``; not one of qpbenchmark's tiers.
- ``high_accuracy``, ``mid_accuracy``, ``low_accuracy``: qpbenchmark's tiers of the same
  names, exactly: each solver's factory defaults (nothing of ``default_settings`` but the
  settings an adapter needs to work, :attr:`required_settings`, none of them about accuracy)
  with the settings qpbenchmark's ``TestSet.define_solver_settings`` gives it (absolute
  tolerances 1e-9, 1e-6, 1e-3, relative ones 0, the duality-gap check of PIQP and ProxQP,
  qpOASES' predefined options, a 10 s time limit); the check's tolerance 1e-9, 1e-6, 1e-3,
  qpbenchmark's validation tolerances of those tiers.
- ``solver_defaults``: qpbenchmark's ``default`` tier: the solvers' factory defaults and
  qpbenchmark's time limit only. The check's tolerance is 1e-3 (qpbenchmark validates that
  tier at 1.0, which would let an answer break a limit by a whole unit).

The per-solver names are transcribed from qpbenchmark 2.7.1's ``SolverSettings``
(``set_eps_abs``, ``set_eps_rel``, ``set_time_limit``) and ``TestSet`` (the tiers; its
default runtime, 10 s); ``tests/solvers/test_settings_tiers.py`` compares every tier with
qpbenchmark's own where it is installed. Settings given explicitly (a scene's
``[solvers.NAME]``, ``--solver-option``) go over the tier's.
"""

from __future__ import annotations

import math
from typing import Any

#: The tiers, the first being the default.
TIERS = ("default", "high_accuracy", "mid_accuracy", "low_accuracy", "solver_defaults")

#: qpbenchmark's name of each of its tiers here.
QPBENCHMARK: dict[str, str] = {
    "high_accuracy": "high_accuracy",
    "mid_accuracy": "mid_accuracy",
    "low_accuracy": "low_accuracy",
    "solver_defaults": "default",
}

#: Absolute tolerance a tier sets (qpbenchmark's ``set_eps_abs``; relative ones are set to 0).
EPS: dict[str, float] = {"high_accuracy": 1e-9, "mid_accuracy": 1e-6, "low_accuracy": 1e-3}

#: The tolerance of the answers' check under each tier but ``default`` (the backend's own).
CHECK: dict[str, float] = {**EPS, "solver_defaults": 1e-3}

#: qpbenchmark's time limit of every tier (``TestSet.define_tolerances``' runtime), s.
TIME_LIMIT = 10.0

#: Per solver, the settings qpbenchmark's ``set_eps_abs`` sets, each to the tier's eps times
#: the factor given.
EPS_ABS: dict[str, dict[str, float]] = {
    "clarabel": {"tol_feas": 1.0, "tol_gap_abs": 1.0},
    "cvxopt": {"feastol": 1.0},
    "daqp": {"dual_tol": 1.0, "primal_tol": 1.0},
    "ecos": {"feastol": 1.0},
    "gurobi": {"FeasibilityTol": 1.0, "OptimalityTol": 1.0},
    "highs": {"dual_feasibility_tolerance": 1.0, "primal_feasibility_tolerance": 1.0},
    "hpipm": {"tol_dual_gap": 1.0, "tol_eq": 1.0, "tol_ineq": 1.0, "tol_stat": 1.0},
    "jaxopt_osqp": {"tol": 1.0},
    "kvxopt": {"feastol": 1.0},
    "osqp": {"eps_abs": 1.0},
    "piqp": {"eps_abs": 1.0, "eps_duality_gap_abs": 1.0},
    "proxqp": {"eps_abs": 1.0, "eps_duality_gap_abs": 1.0},
    "qpalm": {"eps_abs": 1.0},
    "qpax": {"solver_tol": 1.0},
    "qpswift": {"RELTOL": math.sqrt(3.0)},
    "scs": {"eps_abs": 1.0},
    "sip": {"eps_abs": 1.0},
}

#: Per solver, the settings qpbenchmark's ``set_eps_rel`` sets (to 0 in every tier).
EPS_REL: dict[str, tuple[str, ...]] = {
    "clarabel": ("tol_gap_rel",),
    "osqp": ("eps_rel",),
    "piqp": ("eps_duality_gap_rel", "eps_rel"),
    "proxqp": ("eps_duality_gap_rel", "eps_rel"),
    "qpalm": ("eps_rel",),
    "scs": ("eps_rel",),
    "sip": ("eps_rel",),
}

#: Per solver, its time-limit setting (qpbenchmark's ``set_time_limit``), s.
TIME_LIMITS: dict[str, str] = {
    "gurobi": "TimeLimit",
    "highs": "time_limit",
    "osqp": "time_limit",
    "qpalm": "time_limit",
    "qpoases": "time_limit",
    "scs": "time_limit_secs",
    "sip": "time_limit",
}

#: Solvers whose ``check_duality_gap`` qpbenchmark turns on in its accuracy tiers.
DUALITY_GAP_CHECK = ("piqp", "proxqp")

#: qpOASES' ``predefined_options`` in each tier that sets it.
QPOASES_OPTIONS: dict[str, str] = {
    "solver_defaults": "default",
    "high_accuracy": "reliable",
    "low_accuracy": "fast",
}


def solver_settings(solver: str, tier: str) -> dict[str, Any]:
    """The settings qpbenchmark gives ``solver`` in one of its tiers (no tolerance).

    Parameters
    ----------
    solver : str
        A solver name as qpsolvers and qpbenchmark spell it, e.g. ``"osqp"``.
    tier : str
        A tier of :data:`QPBENCHMARK` (dvqp's name).

    Returns
    -------
    dict
        E.g. ``{"eps_abs": 1e-06, "eps_rel": 0.0, "time_limit": 10.0}`` for OSQP at
        ``mid_accuracy``; ``{}`` for a solver qpbenchmark sets nothing of.
    """
    settings: dict[str, Any] = {}
    if tier in EPS:
        eps = EPS[tier]
        settings.update({name: eps * factor for name, factor in EPS_ABS.get(solver, {}).items()})
        settings.update(dict.fromkeys(EPS_REL.get(solver, ()), 0.0))
        if solver in DUALITY_GAP_CHECK:
            settings["check_duality_gap"] = True
    if solver == "qpoases" and tier in QPOASES_OPTIONS:
        settings["predefined_options"] = QPOASES_OPTIONS[tier]
    if solver in TIME_LIMITS:
        settings[TIME_LIMITS[solver]] = TIME_LIMIT
    return settings


def tier_settings(backend: str, tier: str) -> dict[str, Any]:
    """The options (``tolerance`` included) of ``backend`` under ``tier``.

    Parameters
    ----------
    backend : str
        A backend name, e.g. ``"osqp"`` or ``"qpsolvers:osqp"`` (same settings).
    tier : str
        One of :data:`TIERS`.

    Returns
    -------
    dict
        ``{}`` for ``default``; else ``tolerance`` (:data:`CHECK`), ``solver_defaults=True``
        (the backend starts from the solver's factory defaults, not its own) and
        :func:`solver_settings`.

    Raises
    ------
    ValueError
        An unknown tier (the message lists :data:`TIERS`).
    """
    if tier not in TIERS:
        raise ValueError(f"unknown settings tier {tier!r} (tiers: {', '.join(TIERS)})")
    if tier == "default":
        return {}
    solver = backend.removeprefix("qpsolvers:")
    return {"tolerance": CHECK[tier], "solver_defaults": True, **solver_settings(solver, tier)}
