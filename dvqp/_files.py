"""Output files: checked before any work, written atomically (private)."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from dvqp.errors import ParameterError


def output_path(path: str | Path, suffixes: Sequence[str]) -> Path:
    """Check an output file name: a known suffix and an existing folder.

    Raises
    ------
    ParameterError
        ``output: <path>: unknown format '.txt' (use .npz, .csv)`` or ``… no such directory``.
    """
    target = Path(path)
    suffix = target.suffix.lower()
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

    The file appears complete or not at all: on any error the temporary file is removed and an
    existing ``target`` is left as it was. The new file gets the usual mode (``0o666 & ~umask``),
    not ``mkstemp``'s 0600.
    """
    fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=target.suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
