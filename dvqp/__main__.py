"""``python -m dvqp`` and the ``dvqp`` executable: the command line (see :mod:`dvqp.cli`)."""

import contextlib
import os
import sys

from dvqp.cli import main


def command() -> None:
    """Run :func:`dvqp.cli.main` and exit with its code, at once, streams flushed, without the
    interpreter's final clean-up. Every file is complete by then (written atomically, closed),
    every pool and cluster shut down by its own ``with``; what is left to tear down is numba's,
    LLVM's and Pinocchio's objects, which costs 0.2-0.4 s of CPU on every command, and which
    after an interrupt (130), caught mid-way, may fail to be destroyed and print noise (or
    crash) after ``dvqp: interrupted``."""
    code = main()
    if "multiprocessing.util" in sys.modules:  # its own exit clean-up (atexit's), kept:
        with contextlib.suppress(Exception):  # children joined, semaphores released (else
            sys.modules["multiprocessing.util"]._exit_function()  # a tracker warns of leaks)
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


if __name__ == "__main__":
    command()
