"""Output files and folders: checked before any work, written atomically (private)."""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from dvqp.errors import OutputError, ParameterError, one_line


def output_path(path: str | Path, suffixes: Sequence[str]) -> Path:
    """Check an output file name before any work; return it as given.

    The name is resolved first (``.``, ``..``, symbolic links followed: a link's file is
    written, the link kept): it must name a file, not a folder, with a known suffix, in an
    existing folder this process can write in; an existing file must be a regular one that is
    not read-only (it is replaced when the output is written, :func:`atomic_file`).

    Raises
    ------
    ParameterError
        ``output: empty file name``, ``output: <path>: is a directory``, ``… unknown format
        '.txt' (use .npz, .csv)``, ``… symbolic link loop``, ``… not a regular file: not
        replaced``, ``… read-only: not replaced``, ``output: <folder>: no such directory``,
        ``… not a directory``, ``… cannot write here (<reason>)``.
    """
    target = _named(path)
    real = resolved(target)
    if os.path.basename(os.fspath(path)) in ("", ".", "..") or real.is_dir():
        raise ParameterError("output", f"{target}: is a directory")
    suffix = target.suffix.lower()
    if suffix not in suffixes:
        raise ParameterError(
            "output", f"{target}: unknown format {suffix or '(none)'!r} (use {', '.join(suffixes)})"
        )
    if os.path.lexists(real):
        if not real.is_file():
            raise ParameterError("output", f"{target}: not a regular file: not replaced")
        if _read_only(real):
            raise ParameterError("output", f"{target}: read-only: not replaced")
    _writable_folder("output", real.parent if target.is_symlink() else target.parent, real.parent)
    return target


def output_folder(path: str | Path, option: str = "output") -> Path:
    """Check an output folder's name before any work; return the folder it resolves to
    (``.``, ``..`` and symbolic links resolved).

    The folder is new (in an existing folder this process can write in), or an existing one
    that is not read-only and can be written in; whether its contents may be replaced is the
    caller's business. ``option`` names it in messages.

    Raises
    ------
    ParameterError
        ``output: empty file name``, ``output: <path>: not a folder``, ``… symbolic link
        loop``, ``… read-only: not replaced``, ``output: <folder>: no such directory``, ``…
        cannot write here (<reason>)``.
    """
    target = _named(path, option)
    real = resolved(target, option)
    if os.path.lexists(real):
        if not real.is_dir():
            raise ParameterError(option, f"{target}: not a folder")
        if _read_only(real):
            raise ParameterError(option, f"{target}: read-only: not replaced")
        _writable_folder(option, target, real)
    else:
        _writable_folder(option, real.parent if target.is_symlink() else target.parent, real.parent)
    return real


def resolved(target: Path, option: str = "output") -> Path:
    """The file or folder the name ``target`` leads to: absolute, ``.`` and ``..`` resolved,
    symbolic links followed (a dangling link: the file it names)."""
    try:
        os.stat(target)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise ParameterError(option, f"{target}: symbolic link loop") from exc
    except ValueError as exc:  # a NUL in the name
        raise ParameterError(option, f"{one_line(str(target))}: not a file name") from exc
    return Path(os.path.realpath(target))


def _named(path: str | Path, option: str = "output") -> Path:
    """``path`` as a Path; refused if empty (or blank)."""
    if not str(path).strip():
        raise ParameterError(option, "empty file name")
    return Path(path)


def _read_only(path: Path) -> bool:
    """Nobody may write ``path`` (no write permission bit: read-only by intent, even for the
    superuser), or this process may not."""
    return not path.stat().st_mode & 0o222 or not os.access(path, os.W_OK)


def _writable_folder(option: str, shown: Path, folder: Path) -> None:
    """Refuse, naming ``shown``, a ``folder`` that is missing or that cannot take a new file:
    found out now, not after a long run."""
    if not folder.is_dir():
        reason = "not a directory" if os.path.lexists(folder) else "no such directory"
        raise ParameterError(option, f"{shown}: {reason}")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise ParameterError(option, f"{shown}: cannot write here ({exc.strerror})") from exc


@contextlib.contextmanager
def atomic_file(target: Path) -> Iterator[Path]:
    """Yield a temporary path beside the file ``target`` leads to (:func:`resolved`: a
    symbolic link's file, the link kept); on success it replaces that file.

    The file appears complete or not at all: on any error (a full disk, Ctrl-C, ``SIGTERM``
    under :func:`dvqp.cli.progress.interruptible`) the temporary file is removed and an
    existing file is left as it was; an operating-system error raises
    :class:`~dvqp.errors.OutputError`. The new file gets the usual mode
    (``0o666 & ~umask``), not ``mkstemp``'s 0600.
    """
    real = resolved(target)
    try:
        fd, tmp = tempfile.mkstemp(dir=real.parent, prefix=f".{real.name}.", suffix=real.suffix)
        os.close(fd)
    except OSError as exc:
        raise _output_error(target, exc) from exc
    try:
        yield Path(tmp)
        _finish(Path(tmp), real)
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
