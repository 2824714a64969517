"""Output files: checked before any work, written atomically; C output captured (private)."""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from dvqp.errors import OutputError, ParameterError


def output_path(path: str | Path, suffixes: Sequence[str]) -> Path:
    """Check an output file name: a known suffix and an existing folder.

    Raises
    ------
    ParameterError
        ``output: <path>: unknown format '.txt' (use .npz, .csv)``, ``… no such directory``,
        ``… is a directory``, ``output: empty file name``.
    """
    if not str(path).strip():
        raise ParameterError("output", "empty file name")
    target = Path(path)
    suffix = target.suffix.lower()
    if target.is_dir():
        raise ParameterError("output", f"{target}: is a directory")
    if suffix not in suffixes:
        raise ParameterError(
            "output", f"{target}: unknown format {suffix or '(none)'!r} (use {', '.join(suffixes)})"
        )
    if not target.parent.is_dir():
        raise ParameterError("output", f"{target.parent}: no such directory")
    try:  # find out now, not after a long run, that the folder cannot take the file
        with tempfile.TemporaryFile(dir=target.parent):
            pass
    except OSError as exc:
        raise ParameterError(
            "output", f"{target.parent}: cannot write here ({exc.strerror})"
        ) from exc
    return target


@contextlib.contextmanager
def atomic_file(target: Path) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; on success it replaces ``target``.

    The file appears complete or not at all: on any error (a full disk, Ctrl-C) the temporary
    file is removed and an existing ``target`` is left as it was; an operating-system error
    raises :class:`~dvqp.errors.OutputError`. The new file gets the usual mode
    (``0o666 & ~umask``), not ``mkstemp``'s 0600.
    """
    try:
        fd, tmp = tempfile.mkstemp(
            dir=target.parent, prefix=f".{target.name}.", suffix=target.suffix
        )
        os.close(fd)
    except OSError as exc:
        raise _output_error(target, exc) from exc
    try:
        yield Path(tmp)
        _finish(Path(tmp), target)
    except BaseException as exc:
        Path(tmp).unlink(missing_ok=True)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise _output_error(target, exc) from exc
        raise


def _finish(tmp: Path, target: Path) -> None:
    """Flush ``tmp`` to the disk (a full disk may only show here), set its mode, rename it."""
    with open(tmp, "rb") as fh:
        os.fsync(fh.fileno())
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, target)


def _output_error(target: Path, exc: OSError) -> OutputError:
    return OutputError(target, exc.strerror or str(exc) or type(exc).__name__, exc.errno)


@contextlib.contextmanager
def c_output_captured(lines: list[str]) -> Iterator[None]:
    """Keep what C/C++ code (Pinocchio's URDF parser) writes to the file descriptors 1 and 2
    off the terminal: its non-empty lines, white space collapsed, are appended to ``lines``
    when the block ends, also on an error. ``sys.stdout`` and ``sys.stderr`` are flushed
    first; a descriptor that is not open is left alone."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    with tempfile.TemporaryFile() as sink:
        saved: list[tuple[int, int]] = []
        try:
            for fd in (1, 2):
                with contextlib.suppress(OSError):
                    saved.append((fd, os.dup(fd)))
                    os.dup2(sink.fileno(), fd)
            yield
        finally:
            for fd, copy in saved:
                os.dup2(copy, fd)
                os.close(copy)
            sink.seek(0)
            text = sink.read().decode("utf-8", errors="replace")
            lines.extend(" ".join(line.split()) for line in text.splitlines() if line.strip())
