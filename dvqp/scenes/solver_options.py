"""The ``[solvers.<backend>]`` tables of a scene: settings handed to that QP backend.

``[solvers.osqp]`` with ``eps_abs = 1e-6`` gives OSQP that setting whenever the scene runs on
``osqp``. The settings of an installed backend are checked at load (an unknown name is refused
with the backend's accepted settings); those of a backend not installed here are kept unchecked
(the scene may come from another machine) and used where it is installed.
"""

from __future__ import annotations

import math
from typing import Any

from dvqp.errors import BackendError
from dvqp.resolution.registry import PINV, available_resolvers, check_options
from dvqp.scenes.fields import Fields, join, kind

Options = dict[str, dict[str, Any]]
"""Settings by backend name."""


def solver_options(f: Fields, doc: dict[str, Any]) -> Options:
    """The ``[solvers]`` table of a scene document, checked (``{}`` if absent)."""
    table = doc.get("solvers", {})
    if not isinstance(table, dict) or not all(isinstance(v, dict) for v in table.values()):
        f.fail("solvers", f"expected tables of settings ([solvers.osqp]), got {kind(table)}")
    installed = available_resolvers()
    options: Options = {}
    for name, settings in table.items():
        field = join("solvers", name)
        for key, value in settings.items():
            if not setting_value(value):
                f.fail(
                    join(field, key),
                    f"expected a finite number, a boolean or a string, got {kind(value)}",
                )
        if name in installed or name == PINV:
            try:
                check_options(name, settings)
            except BackendError as exc:
                f.fail(field, str(exc))
        options[name] = dict(settings)
    return options


def setting_value(value: object) -> bool:
    """``value`` may be handed to a solver: a bool, an int, a finite float or a string."""
    if isinstance(value, float):
        return math.isfinite(value)
    return isinstance(value, (bool, int, str))
