"""Benchmarks measure this checkout's ``dvqp`` and ``solvers``, never an installed copy.

``python benchmarks/<name>.py`` puts ``benchmarks/`` first on ``sys.path``, not the
repository: ``import dvqp`` would then find whatever is installed (an older release, another
working copy) and measure that. Each benchmark imports this module before ``dvqp``: it puts
the repository's root right after ``benchmarks/`` (so that the benchmarks still import each
other), ahead of the installed packages.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
"""The repository's root (the folder holding ``dvqp/`` and ``solvers/``)."""

if str(ROOT) not in sys.path:
    sys.path.insert(1, str(ROOT))
