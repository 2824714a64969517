"""The versions of dvqp and of what its numbers depend on, for files and reports (private)."""

from __future__ import annotations

import numpy as np

import solvers


def versions() -> dict[str, str]:
    """Versions of dvqp, numpy, pinocchio and the QP solver packages."""
    import pinocchio

    from dvqp import __version__

    out = {"dvqp": __version__, "numpy": np.__version__, "pinocchio": str(pinocchio.__version__)}
    out.update(solvers.backend_versions())
    return out
