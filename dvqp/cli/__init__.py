"""The ``dvqp`` command line: ``plan``, ``compare``, ``plot`` and ``backends``."""

from dvqp.cli.main import main

__all__ = ["main"]
