"""Several kernels in one compiled call: a generated driver over one bag of arrays.

Calling a numba function from Python unboxes each array argument (about 50 ns each): a
step's twenty kernels with some ninety arrays would spend more time crossing into compiled
code than computing. :func:`fuse` generates a module with a :class:`Bag` type for the
kernels' arguments (a numba StructRef holding one tuple of arrays per kind — the same arrays,
shared, not copied — and arrays of the scalar arguments), a ``pack`` function that builds it
once, and a driver ``driver(bag)`` that calls the kernels in order with their arguments taken
from the bag: one call, one cheap unboxing.

The driver's source depends only on which kernels run and where their arguments sit in the
bag, not on the values, so runs of the same composition share it. It is written to a cache
directory (``$DVQP_CACHE_DIR``, else ``$XDG_CACHE_HOME/dvqp`` or ``~/.cache/dvqp``) under a name
that is a hash of its source, and compiled with numba's on-disk cache: the first run of a
composition compiles it (about 1–3 s), later runs load it. Where that is not possible (an
argument of another type, a kernel that is not a module-level numba function, a cache
directory that cannot be written), :func:`fuse` returns a plain loop over the kernels instead:
slower, same results.
"""

from __future__ import annotations

import functools
import hashlib
import importlib.util
import os
import stat
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numba
import numpy as np
from numba import types
from numba.core.registry import CPUDispatcher
from numba.experimental import structref

from dvqp.compiled.buffers import Kernel

KINDS = {
    (np.dtype(np.float64), 1): "f1",
    (np.dtype(np.float64), 2): "f2",
    (np.dtype(np.float64), 3): "f3",
    (np.dtype(np.int64), 1): "i1",
    (np.dtype(np.bool_), 1): "b1",
    (np.dtype(np.bool_), 2): "b2",
}
"""Array kinds a bag holds (dtype, ndim -> field), C-contiguous only."""


@structref.register
class BagType(types.StructRef):
    """numba type of :class:`Bag` (its fields are set by each generated module)."""

    def preprocess_fields(self, fields):  # type: ignore[no-untyped-def]
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class Bag(structref.StructRefProxy):
    """One tuple of arrays per kind of :data:`KINDS` in use, the float scalars ``fs`` and the
    integer scalars ``ns`` of a fused sequence of kernels (built by the generated ``pack``)."""


structref.define_boxing(BagType, Bag)

_ITEM_TYPES = {
    "f1": "types.Array(types.float64, 1, 'C')",
    "f2": "types.Array(types.float64, 2, 'C')",
    "f3": "types.Array(types.float64, 3, 'C')",
    "i1": "types.Array(types.int64, 1, 'C')",
    "b1": "types.Array(types.boolean, 1, 'C')",
    "b2": "types.Array(types.boolean, 2, 'C')",
}


def cache_dir() -> Path:
    """Where generated drivers (and numba's cache of them) are kept."""
    found = os.environ.get("DVQP_CACHE_DIR")
    if found:
        return Path(found)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "dvqp"


def _visible(path: Path, root: Path) -> bool:
    """No part of ``path`` below ``root`` is hidden (an editor's lock file, ``.git``)."""
    return not any(part.startswith(".") for part in path.relative_to(root).parts)


@functools.cache
def _package_fingerprint() -> str | None:
    """A hash of dvqp's source files and the compiler's versions: a driver compiled against
    other kernels' code is never reused (numba's cache of a driver only checks the driver's
    file, not the code it calls). The same for every process of one installation (so they
    share their drivers); None if a file cannot be read (the kernels then run in a plain
    loop)."""
    digest = hashlib.sha256(f"{numba.__version__} {sys.version}".encode())
    root = Path(__file__).resolve().parent.parent
    try:
        files = sorted(p for p in root.rglob("*.py") if _visible(p, root))
        for path in files:
            digest.update(path.read_bytes())
    except OSError:
        return None
    return digest.hexdigest()[:20]


def _module_fingerprint(module: str) -> str | None:
    """A hash of a kernel's module source, or None if it has no file (e.g. ``__main__``
    of an interactive session): such a kernel is not fused."""
    if module.split(".")[0] == "dvqp":
        return "dvqp"
    if module == "__main__":
        return None
    path = getattr(sys.modules.get(module), "__file__", None)
    if path is None:
        return None
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:20]
    except OSError:
        return None


def _private_folder(folder: Path) -> bool:
    """Create ``folder`` (mode 0700) if needed; True if it is a directory of this user that
    nobody else may write (generated code is imported from it), where that can be told."""
    folder.mkdir(parents=True, exist_ok=True, mode=0o700)
    info = folder.stat()
    if not hasattr(os, "getuid"):
        return True
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def _place(arg: Any, lists: dict[str, list[Any]], fs: list[float], ns: list[int]) -> str | None:
    """Put one argument in the bag; its expression in the driver, or None if unsupported
    (supported: the arrays of :data:`KINDS`, bool, int and float scalars, tuples of floats)."""
    if isinstance(arg, np.ndarray):
        kind = KINDS.get((arg.dtype, arg.ndim))
        if kind is None or not arg.flags.c_contiguous:
            return None
        # a read-only array is a constant of the run (dvqp freezes its parameters): packed as
        # a copy, since the bag's lists hold writable arrays
        lists[kind].append(arg if arg.flags.writeable else arg.copy())
        return f"{kind}[{len(lists[kind]) - 1}]"
    if isinstance(arg, bool | np.bool_):
        ns.append(int(arg))
        return f"ns[{len(ns) - 1}] != 0"
    if isinstance(arg, int | np.integer):
        ns.append(int(arg))
        return f"ns[{len(ns) - 1}]"
    if isinstance(arg, float | np.floating):
        fs.append(float(arg))
        return f"fs[{len(fs) - 1}]"
    if isinstance(arg, tuple) and arg and all(isinstance(a, float) for a in arg):
        items = [_place(a, lists, fs, ns) for a in arg]
        return f"({', '.join(items)},)"  # type: ignore[arg-type]
    return None


def _source(kernels: Sequence[Kernel], lists: dict[str, list[Any]], fs: list[float],
            ns: list[int]) -> str | None:  # fmt: skip
    """The module's source, filling the bag's lists; None if a kernel cannot be fused."""
    head = ["from numba import njit, types", "from numba.experimental import structref", "",
            "from dvqp.compiled.fusion import BagType", ""]  # fmt: skip
    package = _package_fingerprint()
    if package is None:
        return None
    prints = {"dvqp": package}
    body: list[str] = []
    for i, kernel in enumerate(kernels):
        f = kernel.function
        py = getattr(f, "py_func", None)
        if not isinstance(f, CPUDispatcher) or py is None:
            return None
        if getattr(sys.modules.get(py.__module__), py.__name__, None) is not f:
            return None
        found = _module_fingerprint(py.__module__)
        if found is None:
            return None
        prints[py.__module__] = found
        head.append(f"from {py.__module__} import {py.__name__} as _k{i}")
        args = [_place(a, lists, fs, ns) for a in kernel.args]
        if any(a is None for a in args):
            return None
        call = f"_k{i}({', '.join(args)})"  # type: ignore[arg-type]
        if kernel.checked:
            body += [f"    status = {call}", "    if status != -1:", "        return status"]
        else:
            body.append(f"    {call}")
    stamp = [f"# {name}: {value}" for name, value in sorted(prints.items())]
    return "\n".join(["# the code this driver was generated against", *stamp, *head,
                      *_bag_source(lists), "", "", "@njit(cache=True)", "def driver(bag):",
                      *(f"    {k} = bag.{k}" for k in _fields(lists)), *body, "    return -1",
                      ""])  # fmt: skip


def _fields(lists: dict[str, list[Any]]) -> list[str]:
    """The bag's fields: the kinds in use, then the scalars."""
    return [k for k in KINDS.values() if lists[k]] + ["fs", "ns"]


def _bag_source(lists: dict[str, list[Any]]) -> list[str]:
    """``BAG`` (the StructRef type of this bag) and ``pack(...)``, which builds one."""
    fields = [f'("{k}", types.UniTuple({_ITEM_TYPES[k]}, {len(lists[k])}))'
              for k in KINDS.values() if lists[k]]  # fmt: skip
    fields += ['("fs", types.Array(types.float64, 1, "C"))',
               '("ns", types.Array(types.int64, 1, "C"))']  # fmt: skip
    names = _fields(lists)
    return ["", "BAG = BagType([", *(f"    {f}," for f in fields), "])", "", "",
            "@njit(cache=True)", f"def pack({', '.join(names)}):", "    bag = structref.new(BAG)",
            *(f"    bag.{k} = {k}" for k in names), "    return bag"]  # fmt: skip


def _load(source: str) -> Any | None:
    """Write ``source`` under its hash (once) and import it; None if impossible."""
    digest = hashlib.sha256(source.encode()).hexdigest()[:20]
    name = f"dvqp_fused_driver_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    try:  # no usable cache (no home, a read-only disk, another's folder): the plain loop
        folder = cache_dir() / "fused"
        path = folder / f"driver_{digest}.py"
        if not _private_folder(folder.parent) or not _private_folder(folder):
            return None
        if not path.exists():  # never rewritten: numba's cache keys on the file's stamp
            part = folder / f".driver_{digest}.{os.getpid()}.tmp"
            part.write_text(source, encoding="utf-8")
            os.replace(part, path)
        if path.read_text(encoding="utf-8") != source:
            return None
    except (OSError, UnicodeError, RuntimeError):  # RuntimeError: Path.home() without a home
        return None
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        return None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # an error in the generated code is dvqp's bug: raised
    sys.modules[name] = module
    return module


def _loop(kernels: Sequence[Kernel]) -> Callable[[], int]:
    calls = [(k.function, k.args, k.checked) for k in kernels]

    def run() -> int:
        for function, args, checked in calls:
            status = function(*args)
            if checked and status != -1:
                return int(status)
        return -1

    run.fused = False  # type: ignore[attr-defined]
    return run


def fuse(kernels: Sequence[Kernel]) -> Callable[[], int]:
    """One call running ``kernels`` in order; it returns −1, or the first status other than
    −1 of a ``checked`` kernel (which stops the sequence there). Its attribute ``fused`` says
    whether it is a generated driver (else a plain loop over the kernels)."""
    lists: dict[str, list[Any]] = {k: [] for k in KINDS.values()}
    fs: list[float] = []
    ns: list[int] = []
    source = _source(kernels, lists, fs, ns)
    module = None if source is None else _load(source)
    if module is None:
        return _loop(kernels)
    parts = [tuple(lists[k]) for k in KINDS.values() if lists[k]]
    bag = module.pack(*parts, np.array(fs, dtype=np.float64), np.array(ns, dtype=np.int64))
    driver = module.driver
    driver.compile((numba.typeof(bag),))  # now, not in the first step (or load the cache)

    def run() -> int:
        return driver(bag)  # type: ignore[no-any-return]

    run.fused = True  # type: ignore[attr-defined]
    return run
