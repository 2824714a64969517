"""Every compiled function of ``solvers`` and ``dvqp``, with an on-disk cache that fails soft.

:func:`njit` is numba's ``njit`` with ``cache=True``; :func:`compiled_on_first_call` the same
for one declared signature, compiled at the first call. Their cache, :class:`SoftCache`, is
numba's own (same folders, same index and data files) with three changes:

- an entry that cannot be loaded (an index or data file cut short, garbled, empty, missing,
  unreadable, of another kind; a data file numba cannot rebuild) is deleted and its function
  compiled anew, with one line on stderr: ``dvqp: note: compile cache entry <file> could not
  be read (<reason>): discarded, compiled again when needed``. The next run finds the
  fresh entry. (A run that only loads the cache, ``ready``, compiles nothing then.)
- an entry that cannot be saved (a full disk) leaves its function compiled for this process
  only, with one note a process; a function that has no folder to cache in is not cached.
- each data file holds the SHA-256 of its contents: machine code cut short or overwritten
  (numba writes by renaming a complete file, but a crash before the disk is flushed can leave
  zeros) is refused before it is loaded, never run. Its index is marked with this format, so
  that numba's plain entries are those of "another version", ignored and overwritten.

:data:`CACHES` lists the caches made, for :func:`entry_files` (``dvqp cache``).
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import os
import pickle
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
from numba import types
from numba.core import sigutils
from numba.core.caching import FunctionCache, IndexDataCacheFile, NullCache
from numba.core.compiler import Flags
from numba.core.compiler_lock import global_compiler_lock
from numba.core.dispatcher import Dispatcher
from numba.core.registry import CPUDispatcher
from numba.core.typing.templates import Signature

from . import frame_chunks, linking

_MAGIC = b"dvqp-sha256\n"
_DIGEST = 32
_FORMAT = "+dvqp-sha256-needs"  # appended to the numba version written at the head of an index
_ENTRY_SUFFIXES = (".nbi", ".nbc")

CACHES: list[SoftCache] = []
"""Every cache made by :func:`njit`, in order."""

_COMPILED = [0]  # kernels compiled in this process (not loaded from the cache)


_NOTED: set[str] = set()  # the notes given once a process


def note(text: str, once: str = "") -> None:
    """``dvqp: note: <text>``, one line on stderr (only the first time for a given ``once``)."""
    if once:
        if once in _NOTED:
            return
        _NOTED.add(once)
    print(f"dvqp: note: {text}", file=sys.stderr, flush=True)


class EntryError(Exception):
    """A data file that is not a whole entry written by :class:`SoftCache`."""


def _reason(exc: BaseException) -> str:
    """A short reason: ``No such file or directory``, ``UnpicklingError: pickle data was
    truncated``, ``checksum mismatch``."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    if isinstance(exc, EntryError):
        return str(exc)
    text = str(exc).splitlines()[0][:100] if str(exc) else ""
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class _EntryFiles(IndexDataCacheFile):
    """numba's index and data files of one function, checksummed; an unreadable one is deleted."""

    def __init__(self, cache_path: str, filename_base: str, source_stamp: Any) -> None:
        super().__init__(cache_path, filename_base, source_stamp)
        self._version = numba.__version__ + _FORMAT

    def entry(self, key: Any) -> tuple[str, Any] | None:
        """``(data file, its unpickled contents)`` of ``key``, or None if there is none (or it
        could not be read: then it is discarded)."""
        try:
            name = self._load_index().get(key)
        except Exception as exc:  # cut short, garbled, unreadable: any error means unusable
            self.discard(self._index_path, exc)
            return None
        if name is None:
            return None
        path = self._data_path(name)
        try:
            return path, self._load_data(name)
        except Exception as exc:
            self.discard(path, exc)
            return None

    def discard(self, path: str, exc: BaseException) -> None:
        """Delete ``path`` (if it can be) and say so."""
        with contextlib.suppress(OSError):
            os.unlink(path)
        note(
            f"compile cache entry {path} could not be read ({_reason(exc)}): "
            "discarded, compiled again when needed"
        )

    def _load_data(self, name: str) -> Any:
        with open(self._data_path(name), "rb") as fh:
            raw = fh.read()
        if not raw:
            raise EntryError("empty file")
        if raw[: len(_MAGIC)] != _MAGIC:
            raise EntryError("not a checksummed entry")
        digest, payload = raw[len(_MAGIC) :][:_DIGEST], raw[len(_MAGIC) + _DIGEST :]
        if hashlib.sha256(payload).digest() != digest:
            raise EntryError("checksum mismatch: cut short or overwritten")
        return pickle.loads(payload)

    def _save_data(self, name: str, data: Any) -> None:
        payload = self._dump(data)
        with self._open_for_write(self._data_path(name)) as fh:
            fh.write(_MAGIC + hashlib.sha256(payload).digest() + payload)


class SoftCache(FunctionCache):
    """numba's ``FunctionCache`` of ``py_func`` whose entries fail soft (see the module)."""

    def __init__(self, py_func: Callable[..., Any]) -> None:
        super().__init__(py_func)
        self.source = inspect.getfile(py_func)
        self._cache_file = _EntryFiles(
            self._cache_path, self._impl.filename_base, self._impl.locator.get_source_stamp()
        )

    def _load_overload(self, sig: Any, target_context: Any) -> Any:
        if not self._enabled:
            return None
        found = self._cache_file.entry(self._index_key(sig, target_context.codegen()))
        if found is None:
            return None
        try:
            needs, reduced = found[1]
            needs = [linking.need(item) for item in needs]
        except (TypeError, ValueError) as exc:  # unpickled, but not an entry of this format
            self._cache_file.discard(found[0], exc)
            return None
        if not linking.provide(needs):  # a kernel its code calls changed its signature
            return None
        try:
            cres = self._impl.rebuild(target_context, reduced)
        except Exception as exc:  # unpickled, but not a compiled function numba can load
            self._cache_file.discard(found[0], exc)
            return None
        linking.record(cres.library, needs)
        return cres

    def _index_key(self, sig: Any, codegen: Any) -> Any:
        """numba's key, marked for an overload compiled for compiled callers only (no CPython
        wrapper: :class:`KernelDispatcher`), so that a Python call never loads one."""
        key = super()._index_key(sig, codegen)
        return (*key, "native") if linking.is_native_only() else key

    def _save_overload(self, sig: Any, data: Any) -> None:
        """numba's, the entry holding the symbols its code calls (:mod:`solvers.linking`)."""
        if not self._enabled or not self._impl.check_cachable(data):
            return
        self._impl.locator.ensure_cache_path()
        key = self._index_key(sig, data.codegen)
        needs = linking.needed_by(data.library)
        self._cache_file.save(key, (needs, self._impl.reduce(data)))

    def save_overload(self, sig: Any, data: Any) -> None:
        try:
            super().save_overload(sig, data)
        except Exception as exc:  # a full disk: compiled all the same, not cached
            note(
                f"compile cache not written ({self._cache_path}: {_reason(exc)}): "
                "compiled code is not cached",
                once="unsaved",
            )


def _cache_for(function: Callable[..., Any]) -> SoftCache | NullCache:
    """The soft cache of ``function``, or no cache if no folder can hold it."""
    try:
        cache = SoftCache(function)
    except (RuntimeError, OSError) as exc:  # no writable folder: numba itself would refuse
        note(f"no compile cache ({exc}): compiled code is not cached", once="uncached")
        return NullCache()
    CACHES.append(cache)
    return cache


class _Flags(Flags):  # type: ignore[misc]
    """numba's compile flags, their values read once per change.

    numba keys its cache of resolved overloads by the flags of the compile under way, and
    hashes and compares them (``TargetConfig.values()``: every one of ~45 options read through
    a property) at every overload it resolves: 10-20 % of compiling dvqp's kernels. The values
    are the same; only reading them is memoised (again whenever the set options change)."""

    __slots__ = ("_memo",)

    def values(self) -> dict[str, Any]:
        memo = getattr(self, "_memo", None)
        if memo is None or memo[0] != self._values:
            memo = self._memo = (dict(self._values), super().values())
        return memo[1]  # type: ignore[no-any-return]


def _flags(flags: Flags) -> _Flags:
    """A compile's flags (:class:`_Flags`), without the CPython wrapper when the compile is
    for compiled callers only (:func:`solvers.linking.native_only`)."""
    made = _Flags(flags)
    if linking.is_native_only():
        made.no_cpython_wrapper = True
    return made


class KernelDispatcher(CPUDispatcher):  # type: ignore[misc]
    """numba's CPU dispatcher, compiled for the plain types of a compiled caller's arguments,
    without a CPython wrapper until Python calls it.

    numba compiles a function called from compiled code for its arguments' types as typed
    there, a constant as its literal type: ``f(x, True)`` and ``f(x, False)`` were two
    specialisations of ``f`` and of everything it calls (with a cold cache, seconds). No
    kernel here asks for a literal, so a call is typed with each argument's plain type (one
    specialisation; the constant is converted at the call).

    numba also wraps every compile for calls from Python (about 20 ms of a small kernel's
    compile), yet most kernels are only ever called from compiled code. A compile for a
    compiled caller (or for :mod:`solvers.linking`) has no wrapper and is cached under a key
    of its own; the first Python call of such an overload compiles (or loads) the wrapped
    one, which then serves both. A kernel that Python calls in every run as well (a NumPy view
    the start's checks use) is declared ``njit(python=True)`` and always compiled wrapped.
    """

    separate = False
    """Whether compiled callers call it through its symbol (:mod:`solvers.linking`)."""
    python = False
    """Whether Python calls it in every run too: always compiled with the CPython wrapper."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._compiler._customize_flags = _flags  # its compiles' flags, and those they nest
        self._native_only: set[tuple[Any, ...]] = set()
        self._unwrapped: list[Any] = []  # replaced overloads: compiled callers hold their code

    def get_call_template(self, args: tuple[Any, ...], kws: dict[str, Any]) -> Any:
        plain = tuple(types.unliteral(a) for a in args)
        with linking.for_callers(self):
            return super().get_call_template(plain, {k: types.unliteral(v) for k, v in kws.items()})

    def compile(self, sig: Any) -> Any:
        if not linking.is_native_only():
            args = tuple(sigutils.normalize_signature(sig)[0])
            if args in self._native_only:  # a Python call: the wrapped overload replaces it
                with global_compiler_lock:
                    if args in self._native_only:
                        self._unwrapped.append(self.overloads.pop(args))
                        self._native_only.discard(args)
        misses = sum(self._cache_misses.values())
        try:
            with frame_chunks.kept():  # numba's deep recursion maps no frame chunk a call
                return super().compile(sig)
        finally:
            if sum(self._cache_misses.values()) > misses:
                _COMPILED[0] += 1

    def add_overload(self, cres: Any) -> None:
        args = tuple(cres.signature.args)
        if cres.objectmode or not linking.is_native_only():
            super().add_overload(cres)
            return
        self._native_only.add(args)  # not callable from Python: kept out of numba's table
        self.overloads[args] = cres


class SeparateDispatcher(KernelDispatcher):
    """A :class:`KernelDispatcher` compiled and cached on its own: a compiled caller calls it
    through its symbol instead of linking its code in (:mod:`solvers.linking`)."""

    separate = True

    def add_overload(self, cres: Any) -> None:
        super().add_overload(cres)
        if not cres.objectmode:
            linking.expose(self, cres)


def njit(
    function: Callable[..., Any] | None = None, *, separate: bool = False, **options: Any
) -> Any:
    """``numba.njit(cache=True, **options)``, its cache a :class:`SoftCache`, without the
    C-callable wrapper numba adds to every compile for first-class function values (nothing
    here takes a dispatcher as a value: compiled callers call a kernel directly or through its
    symbol, :mod:`solvers.linking`); it cost about 20 ms of every compile, 1.5-2 s of a cold
    plan.

    Use as ``@njit``, ``@njit(inline="always")``, ``@njit(python=True)`` (see
    :class:`KernelDispatcher`) or ``@njit(separate=True)`` (a kernel
    compiled and cached on its own, :class:`SeparateDispatcher`); compiles at the first call, as
    numba's.
    """
    if "cache" in options:
        raise TypeError("njit: always cached, no 'cache' option")
    if separate and options.get("inline", "never") != "never":
        raise TypeError("njit: a separate kernel is never inlined")

    python = options.pop("python", False)

    def decorate(f: Callable[..., Any]) -> KernelDispatcher:
        kind = SeparateDispatcher if separate else KernelDispatcher
        targetoptions = {"nopython": True, "no_cfunc_wrapper": True, **options}
        dispatcher = kind(py_func=f, locals={}, targetoptions=targetoptions)
        dispatcher.python = python
        dispatcher._cache = _cache_for(f)  # what numba's enable_caching() sets, soft
        return dispatcher

    return decorate if function is None else decorate(function)


def compiled_count() -> int:
    """The kernels :func:`njit` compiled in this process so far (those loaded from the
    cache are not counted)."""
    return _COMPILED[0]


def ready(dispatcher: Dispatcher, args: tuple[Any, ...]) -> bool:
    """Whether a call ``dispatcher(*args)`` from Python runs without compiling: its overload
    for these arguments' types is compiled in this process, or is loaded now from the cache
    (as numba's ``Dispatcher.compile`` loads it). Never compiles that overload (a separate
    kernel its cached code calls is compiled if the cache has lost it,
    :func:`solvers.linking.provide`)."""
    argtypes = tuple(dispatcher.typeof_pyval(a) for a in args)
    with global_compiler_lock:
        if argtypes in getattr(dispatcher, "_native_only", ()) or linking.is_native_only():
            return False  # compiled callers' code only: a Python call compiles its wrapper
        if argtypes in dispatcher.overloads:
            return True
        cres = dispatcher._cache.load_overload(argtypes, dispatcher.targetctx)
        if cres is None:
            return False
        dispatcher._cache_hits[argtypes] += 1
        if not cres.objectmode:
            dispatcher.targetctx.insert_user_function(cres.entry_point, cres.fndesc, [cres.library])
        dispatcher.add_overload(cres)
        return True


def entry_files(roots: list[Path]) -> dict[Path, list[Path]]:
    """Cache folder -> its entry files (index, data and leftover temporary files) of the
    modules under ``roots`` that made a cache here; other files are never listed."""
    stems: dict[Path, set[str]] = {}
    for cache in CACHES:
        source = Path(cache.source).resolve()
        if any(source.is_relative_to(root.resolve()) for root in roots):
            stems.setdefault(Path(cache.cache_path), set()).add(source.stem)
    found = {}
    for folder, names in sorted(stems.items()):
        files = sorted(folder.iterdir()) if folder.is_dir() else []
        found[folder] = [
            p
            for p in files
            if p.is_file()
            and p.name.split(".")[0] in names
            and any(p.name.endswith(s) or f"{s}.tmp." in p.name for s in _ENTRY_SUFFIXES)
        ]
    return found


def compiled_on_first_call(
    signature: Signature, **options: Any
) -> Callable[[Callable[..., Any]], Dispatcher]:
    """``njit(signature, cache=True, **options)``, compiled at the first call, not at import.

    ``njit`` given a signature compiles it (or loads it from numba's on-disk cache) when the
    module is imported: seconds of CPU with an empty cache, in every process that imports
    ``solvers``, whether it solves anything or not. A plain lazy ``njit`` would instead compile
    one specialisation per distinct argument types, and writable and read-only arrays are
    distinct types: twice the compile time for a kernel called with both.

    The dispatcher returned compiles nothing until it is called. Its first call compiles
    ``signature`` alone (or loads it from the cache) and then disables compilation, as
    ``njit(signature)`` does at import: from then on, that first call included, arguments
    are converted to the signature (a writable array passes as a read-only one) or refused
    with ``TypeError``, and there is one specialisation, however the function is called.

    Parameters
    ----------
    signature : numba Signature
        The one signature to compile, e.g. ``types.boolean(types.float64[::1])``.
    **options
        Further ``njit`` options (e.g. ``fastmath``); the cache is always a :class:`SoftCache`.

    Returns
    -------
    callable
        A decorator turning a function into its numba dispatcher.

    Notes
    -----
    The hook is the dispatcher's ``_compile_for_args``, which numba calls only when no compiled
    overload fits the arguments and compilation is enabled, i.e. only until the first call
    has compiled. Replacing it returns the dispatcher itself, which numba then calls again with
    the same arguments: now a typed call of the one overload. Concurrent first calls are safe:
    a lock lets one thread compile, the others then find compiling done (without it, numba
    refused their ``compile`` with ``RuntimeError('compilation disabled')``, e.g. in a Dask
    worker's threads). Meant for functions called
    from Python: numba's typing of a call from other jitted code would compile the callee for
    the caller's argument types instead. ``tests/solvers/test_structure.py`` checks, in a fresh
    interpreter, that importing compiles nothing and that each kernel ends with one overload.
    """

    def decorate(function: Callable[..., Any]) -> Dispatcher:
        dispatcher: Dispatcher = njit(**options)(function)
        first = threading.Lock()

        def compile_declared(*args: Any, **kwargs: Any) -> Dispatcher:
            with first:  # a thread that waited finds it compiled (compiling is then disabled)
                if dispatcher._can_compile:
                    dispatcher.compile(signature)
                    dispatcher.disable_compile()
            return dispatcher

        dispatcher._compile_for_args = compile_declared
        return dispatcher

    return decorate
