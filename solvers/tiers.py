"""Settings tiers: qpbenchmark's ``default``, ``high_accuracy`` and ``low_accuracy``.

A tier is a set of solver settings plus the tolerance of :mod:`solvers`' own check of every
answer (:attr:`Backend.tolerance <solvers.Backend.tolerance>`), so that a solver is asked for
the accuracy its answer is then held to:

- ``default``: each backend's own defaults in :mod:`solvers` (tuned so that every backend
  reaches ~1e-7 on ``x`` on dvqp-sized problems; the check's tolerance is 1e-6). These are
  not the solvers' factory defaults, which are looser.
- ``high_accuracy``: absolute tolerances 1e-9 and relative tolerances 0 (qpbenchmark's
  ``high_accuracy`` values); the check's tolerance 1e-9.
- ``low_accuracy``: absolute tolerances 1e-3, relative 0 (qpbenchmark's ``low_accuracy``);
  the check's tolerance 1e-3.

:data:`SETTING_NAMES` lists, per solver, the settings a tier sets to its ``eps`` (absolute)
or to 0 (relative), the names qpbenchmark sets for the same solvers. quadprog and other
solvers without accuracy settings get the check's tolerance only. Settings given explicitly
(a scene's ``[solvers.NAME]``, ``--solver-option``) go over the tier's.
"""

from __future__ import annotations

from typing import Any

#: The tiers, the first being the default.
TIERS = ("default", "high_accuracy", "low_accuracy")

#: Absolute tolerance of each tier but ``default``.
EPS: dict[str, float] = {"high_accuracy": 1e-9, "low_accuracy": 1e-3}

#: Per solver: (settings set to the tier's eps, settings set to 0, settings set to True).
SETTING_NAMES: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]] = {
    "clarabel": (("tol_feas", "tol_gap_abs"), ("tol_gap_rel",), ()),
    "daqp": (("primal_tol", "dual_tol"), (), ()),
    "highs": (("primal_feasibility_tolerance", "dual_feasibility_tolerance"), (), ()),
    "osqp": (("eps_abs",), ("eps_rel",), ()),
    "piqp": (
        ("eps_abs", "eps_duality_gap_abs"),
        ("eps_rel", "eps_duality_gap_rel"),
        ("check_duality_gap",),
    ),
    "proxqp": (
        ("eps_abs", "eps_duality_gap_abs"),
        ("eps_rel", "eps_duality_gap_rel"),
        ("check_duality_gap",),
    ),
}


def tier_settings(backend: str, tier: str) -> dict[str, Any]:
    """The settings (``tolerance`` included) of ``backend`` under ``tier``.

    Parameters
    ----------
    backend : str
        A backend name, e.g. ``"osqp"`` or ``"qpsolvers:osqp"`` (same settings).
    tier : str
        One of :data:`TIERS`.

    Returns
    -------
    dict
        ``{}`` for ``default``; else ``tolerance`` and the solver's settings of the tier.

    Raises
    ------
    ValueError
        An unknown tier (the message lists :data:`TIERS`).
    """
    if tier not in TIERS:
        raise ValueError(f"unknown settings tier {tier!r} (tiers: {', '.join(TIERS)})")
    if tier == "default":
        return {}
    eps = EPS[tier]
    absolute, relative, switches = SETTING_NAMES.get(
        backend.removeprefix("qpsolvers:"), ((), (), ())
    )
    return {
        "tolerance": eps,
        **dict.fromkeys(absolute, eps),
        **dict.fromkeys(relative, 0.0),
        **dict.fromkeys(switches, True),
    }
