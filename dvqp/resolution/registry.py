"""Resolver names, resolved in one place: the ``pinv`` baseline beside every QP backend.

Every name a user types (``dvqp plan --backend``, :func:`dvqp.plan`, ``dvqp compare``) goes
through :func:`make_resolver`; an unknown one raises :class:`~dvqp.errors.BackendError`
listing what is installed and the extra that installs more.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import solvers
from dvqp import _validate
from dvqp._versions import __version__
from dvqp.errors import BackendError, ParameterError
from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.qp import QPResolver, make_backend
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver
from solvers.tiers import TIERS, tier_settings

PINV = "pinv"
"""Name of the paper's pseudoinverse baseline (eq. 18)."""

PINV_SETTINGS = ("damping",)
"""The settings the baseline takes: ``damping`` (μ >= 0 of its damped inverse, 0 its
default)."""

EXTRA_BACKENDS = ("proxqp", "quadprog", "piqp", "highs")
"""The backends the extra ``dvqp[solvers]`` installs."""


@dataclass(frozen=True)
class ResolverInfo:
    """What ``dvqp backends`` prints about one name: the ``name`` to pass to
    :func:`make_resolver`, the Python ``distribution`` that provides it, its installed
    ``version`` (``"?"`` if unknown) and a ``note`` on how it is reached, e.g.
    ``"via qpsolvers 4.13.0"`` or ``"pseudoinverse baseline"``."""

    name: str
    distribution: str
    version: str
    note: str


def available_resolvers() -> list[str]:
    """Every name :func:`make_resolver` accepts here: ``pinv`` first, then the QP backends."""
    return [PINV, *solvers.available_backends()]


def default_resolvers() -> list[str]:
    """``pinv`` and every installed plain QP backend name (no ``qpsolvers:`` prefix)."""
    return [PINV, *(b for b in solvers.available_backends() if ":" not in b)]


def describe_resolvers() -> list[ResolverInfo]:
    """One :class:`ResolverInfo` per name of :func:`available_resolvers`, in that order."""
    infos = [ResolverInfo(PINV, "dvqp", __version__, "pseudoinverse baseline, paper eq. 18")]
    for b in solvers.describe_backends():
        infos.append(ResolverInfo(b.name, b.distribution, b.version, b.note))
    return infos


def check_name(name: str) -> str:
    """``name`` if :func:`make_resolver` knows it.

    Raises
    ------
    BackendError
        Unknown or not installed: the message lists the installed names and the extra.
    """
    known = available_resolvers()
    if name not in known:
        missing = [b for b in EXTRA_BACKENDS if b not in known]
        hint = f" (pip install 'dvqp[solvers]' for {', '.join(missing)})" if missing else ""
        raise BackendError(f"unknown backend {name!r}; installed: {', '.join(known)}{hint}")
    return name


def check_options(name: str, options: dict[str, Any]) -> dict[str, Any]:
    """``options`` if the backend ``name`` takes them (a backend is made with them once).

    Raises
    ------
    BackendError
        Unknown backend; a setting the backend does not take (its accepted settings listed
        where the backend can say them; ``pinv`` takes :data:`PINV_SETTINGS`).
    """
    check_name(name)
    if name == PINV:
        unknown = sorted(set(options) - set(PINV_SETTINGS))
        if unknown:
            raise BackendError(
                f"pinv: unknown setting {unknown[0]!r}; the pseudoinverse takes: "
                f"{', '.join(PINV_SETTINGS)}"
            )
        for key, value in options.items():
            try:
                _validate.positive(key, value, strict=False)
            except (ParameterError, TypeError, ValueError) as exc:
                raise BackendError(f"pinv: {key} must be a number >= 0, got {value!r}") from exc
        return options
    make_backend(name, **options)
    return options


def tier_options(name: str, tier: str) -> dict[str, Any]:
    """The settings of backend ``name`` under the settings ``tier`` (:mod:`solvers.tiers`;
    none for the baseline, which has no settings).

    Raises
    ------
    ParameterError
        ``settings: unknown tier 'x' (tiers: default, high_accuracy, …)``.
    """
    if tier not in TIERS:
        raise ParameterError("settings", f"unknown tier {tier!r} (tiers: {', '.join(TIERS)})")
    return {} if name == PINV else tier_settings(name, tier)


def make_resolver(name: str, spec: StepSpec, options: dict[str, Any] | None = None) -> Resolver:
    """A fresh resolver of ``spec`` by name.

    Parameters
    ----------
    name
        ``"pinv"`` or a QP backend name of :func:`solvers.available_backends`.
    spec
        The tasks, objective, limits and weights of the step.
    options
        Settings of the QP backend (``{"eps_abs": 1e-6}``), checked (:func:`check_options`).

    Raises
    ------
    BackendError
        Unknown or not installed (see :func:`check_name`), or settings it does not take.
    """
    check_name(name)
    if name == PINV:
        settings = check_options(name, options or {})
        return PseudoinverseResolver(spec, **{k: float(v) for k, v in settings.items()})
    return QPResolver(spec, name, options)  # makes its backend once: the settings checked there
