"""``python -m dvqp`` and the ``dvqp`` executable: the command line (see :mod:`dvqp.cli`)."""

import contextlib
import os
import sys

from dvqp.cli import main


def command() -> None:
    """Run :func:`dvqp.cli.main` and exit with its code. After an interrupt (130) the process
    ends at once, streams flushed, without the interpreter's final clean-up: numba's and LLVM's
    objects caught mid-way by the interrupt may fail to be destroyed and would print noise (or
    crash) after ``dvqp: interrupted``."""
    code = main()
    if code == 130:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(130)
    sys.exit(code)


if __name__ == "__main__":
    command()
