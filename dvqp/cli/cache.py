"""``dvqp cache path`` and ``dvqp cache clear``: where numba keeps dvqp's compiled code, and
deleting it (never other files). See ``docs/compiled.md``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import solvers
from dvqp.errors import DvqpError
from solvers.jit import entry_files

ROOTS = [Path(__file__).parent.parent, Path(solvers.__file__).parent]
"""The packages whose compiled functions the cache commands see."""


def register(subparsers: Any) -> None:
    """Add ``cache path`` and ``cache clear`` to ``subparsers`` (of ``dvqp``'s parser)."""
    c = subparsers.add_parser("cache", help="where dvqp's compiled code is cached; clear it")
    actions = c.add_subparsers(title="actions", metavar="ACTION", required=True)
    p = actions.add_parser("path", help="print the folders of dvqp's compile cache")
    p.set_defaults(run=show_path)
    r = actions.add_parser("clear", help="delete dvqp's compile cache entries (only those)")
    r.set_defaults(run=clear)


def show_path(args: argparse.Namespace) -> int:
    """Print each folder holding (or to hold) compiled functions of dvqp, one a line: under
    ``NUMBA_CACHE_DIR`` if it is set, else each source folder's ``__pycache__`` (or numba's
    user-wide cache folder where that cannot be written)."""
    for folder in _entries():
        print(folder)
    return 0


def clear(args: argparse.Namespace) -> int:
    """Delete every cache entry of dvqp's compiled functions (index, data and leftover
    temporary files) and print how many files and bytes; exit 1 if one could not be deleted
    (``dvqp: <file>: cannot remove: <reason>``), after deleting the others."""
    count = size = failed = 0
    for files in _entries().values():
        for path in files:
            try:
                nbytes = path.stat().st_size
                path.unlink()
            except FileNotFoundError:  # removed meanwhile (another process)
                continue
            except OSError as exc:
                print(f"dvqp: {path}: cannot remove: {exc.strerror or exc}", file=sys.stderr)
                failed += 1
            else:
                count, size = count + 1, size + nbytes
    print(f"removed {count} compile cache files ({size:,} bytes)")
    return 1 if failed else 0


def _entries() -> dict[Path, list[Path]]:
    """:func:`solvers.jit.entry_files` of dvqp; an unreadable folder is a :class:`DvqpError`."""
    try:
        return entry_files(ROOTS)
    except OSError as exc:
        raise DvqpError(f"{exc.filename}: cannot read: {exc.strerror or exc}") from exc
