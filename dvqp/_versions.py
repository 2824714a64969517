"""The versions of dvqp and of what its numbers depend on, for files and reports (private)."""

from __future__ import annotations

import numpy as np
import pinocchio

import solvers

__version__ = "0.2.0"
"""dvqp's version (also ``dvqp.__version__``)."""


def versions() -> dict[str, str]:
    """Versions of dvqp, numpy, pinocchio and the QP solver packages."""
    out = {"dvqp": __version__, "numpy": np.__version__, "pinocchio": str(pinocchio.__version__)}
    out.update(solvers.backend_versions())
    return out
