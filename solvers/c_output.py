"""What C and C++ code prints, kept off the terminal.

A solver library (OSQP, HiGHS) or Pinocchio's URDF parser prints with ``printf`` (below
Python's ``sys.stdout``) or through ``sys.stdout`` from C (OSQP's ``PySys_WriteStdout``):
:func:`c_output_captured` catches both, so that a caller can report it in its own words
(OSQP's reason for refusing a setting) or drop it.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import tempfile
from collections.abc import Iterator


@contextlib.contextmanager
def c_output_captured(lines: list[str]) -> Iterator[None]:
    """Keep what C/C++ code (Pinocchio's URDF parser, a solver library) writes off the
    terminal: to the file descriptors 1 and 2, and to ``sys.stdout`` and ``sys.stderr`` (an
    extension's ``PySys_WriteStdout``, which OSQP prints with). Its non-empty lines, white
    space collapsed, are appended to ``lines`` when the block ends, also on an error.

    ``sys.stdout``, ``sys.stderr`` and the C library's own buffers (``printf`` to a file or a
    pipe is buffered) are flushed first, and the C buffers again before the descriptors are
    given back, so nothing printed inside reaches them later; a descriptor that is not open
    is left alone."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    _flush_c()
    python = io.StringIO()
    with tempfile.TemporaryFile() as sink:
        saved: list[tuple[int, int]] = []
        try:
            for fd in (1, 2):
                with contextlib.suppress(OSError):
                    saved.append((fd, os.dup(fd)))
                    os.dup2(sink.fileno(), fd)
            with contextlib.redirect_stdout(python), contextlib.redirect_stderr(python):
                yield
        finally:
            _flush_c()
            for fd, copy in saved:
                os.dup2(copy, fd)
                os.close(copy)
            sink.seek(0)
            text = python.getvalue() + sink.read().decode("utf-8", errors="replace")
            lines.extend(" ".join(line.split()) for line in text.splitlines() if line.strip())


def _flush_c() -> None:
    """``fflush(NULL)``: the C library's buffered output written out (nothing where the C
    library cannot be reached)."""
    with contextlib.suppress(AttributeError, OSError, TypeError):
        import ctypes

        ctypes.CDLL(None).fflush(None)
