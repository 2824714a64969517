"""``--backends LIST``, ``--solver-option NAME.KEY=VALUE`` and ``--settings TIER``: which
backends run and their settings, from the command line."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from typing import Any

from dvqp.errors import ParameterError
from dvqp.resolution.registry import check_options
from dvqp.scenes.solver_options import setting_value
from solvers.tiers import TIERS

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

FLAG = "--solver-option"


def add_argument(parser: argparse.ArgumentParser) -> None:
    """The repeatable ``--solver-option`` and the ``--settings`` tier of ``plan``, ``compare``
    and ``bench``."""
    parser.add_argument(
        FLAG,
        action="append",
        default=[],
        metavar="NAME.KEY=VALUE",
        help="a setting of a QP backend, e.g. osqp.eps_abs=1e-6 (repeatable; "
        "over the scene's [solvers.NAME])",
    )
    parser.add_argument(
        "--settings",
        choices=TIERS,
        default=TIERS[0],
        help="accuracy tier of every QP backend: its solver settings and the tolerance "
        "answers are checked to. default: dvqp's own (tighter than the solvers' "
        "defaults); high_accuracy, mid_accuracy, low_accuracy: qpbenchmark's tiers, "
        "exactly; solver_defaults: qpbenchmark's default tier, each solver's own "
        "defaults (see docs/cli.md)",
    )


def backend_list(text: str | None) -> list[str] | None:
    """The names ``--backends`` lists (None when it is not given: the default backends).

    Raises
    ------
    ParameterError
        ``--backends: empty list: name at least one backend (dvqp backends lists them)``, or
        ``--backends: 'pinv,,daqp': an empty name``.
    """
    if text is None:
        return None
    names = [name.strip() for name in text.split(",")]
    if not any(names):
        raise ParameterError(
            "--backends", "empty list: name at least one backend (dvqp backends lists them)"
        )
    if not all(names):
        raise ParameterError("--backends", f"{text!r}: an empty name")
    return names


def solver_options(values: Sequence[str], backends: Sequence[str]) -> dict[str, dict[str, Any]]:
    """The settings given, by backend, each checked against the backend (nothing run yet).

    A value is read as a TOML value (``1e-6``, ``true``, ``"qdldl"``), else taken as text.

    Raises
    ------
    ParameterError
        ``--solver-option: osqp.eps_abs: …`` (not ``NAME.KEY=VALUE``, a backend not run).
    BackendError
        A setting the backend does not take (its accepted settings listed).
    """
    options: dict[str, dict[str, Any]] = {}
    for text in values:
        target, sep, raw = text.partition("=")
        name, dot, key = target.strip().rpartition(".")
        if not (sep and dot and name and key):
            raise ParameterError(FLAG, f"{text!r}: expected NAME.KEY=VALUE, e.g. osqp.eps_abs=1e-6")
        if name not in backends:
            raise ParameterError(
                FLAG, f"{text!r}: {name} is not run here (backends: {', '.join(backends)})"
            )
        try:
            value = tomllib.loads(f"v = {raw.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw.strip()
        if not setting_value(value):
            raise ParameterError(FLAG, f"{text!r}: expected a finite number, a boolean or text")
        options.setdefault(name, {})[key] = value
    for name, settings in options.items():
        check_options(name, settings)
    return options
