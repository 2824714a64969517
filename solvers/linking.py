"""Kernels compiled and cached on their own: compiled code calls them without linking them in.

numba links the code of every jitted function a jitted function calls into the caller's own
module, optimises that module again and generates its machine code again: a pipeline five
calls deep has its leaves compiled five times over, and its entry point holds a copy of
everything. This module gives compiled code two ways to call compiled code that is not
linked in:

- a **separate kernel** (:func:`solvers.jit.njit` with ``separate=True``) is called through
  a symbol: its callers declare ``dvqp.kernel.<hash>`` and call it; the symbol is made known
  to LLVM's linker (``llvmlite.binding.add_symbol``) when the kernel is compiled or loaded
  from the cache. A caller's cache entry lists the symbols its code needs
  (:func:`needed_by`), and the cache provides them before that entry is loaded
  (:func:`provide`): a symbol's name holds the kernel's module, name and whole signature
  (return type included), so an entry whose kernel has changed its signature is compiled
  anew rather than bound to the wrong code, and one whose kernel has changed its body calls
  the new body.
- an **indirect call** (:func:`indirect`) calls a kernel whose address compiled code reads
  at run time (from an array): :func:`address_of` compiles (or loads) the kernel for the
  very argument types the call passes. The caller's code names no kernel at all, so only
  the kernels a run uses are ever compiled (an obstacle shape's kind, say).

Both call numba's own native calling convention (the one a linked call uses): an exception
raised in the kernel propagates to its caller as from a linked call.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import threading
from collections.abc import Callable, Iterable, Iterator
from typing import Any

import llvmlite.binding as llvm
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.base import OverloadSelector
from numba.core.compiler_lock import global_compiler_lock
from numba.core.extending import intrinsic
from numba.core.imputils import fix_returning_optional, impl_ret_new_ref
from numba.core.registry import cpu_target
from numba.core.runtime import rtsys
from numba.core.typing import signature

Need = tuple[str, str, tuple[Any, ...], str]
"""What a cache entry's code needs: ``(module, name, argument types, symbol)`` of a separate
kernel."""

_EXPOSED: dict[str, int] = {}
"""Symbols made known to LLVM in this process, with their addresses."""

_MODE = threading.local()


@contextlib.contextmanager
def native_only(native: bool = True) -> Iterator[None]:
    """Compiles started in this block (on this thread) are for compiled callers only: without
    numba's CPython wrapper (:class:`solvers.jit.KernelDispatcher`); ``native=False``: with
    it, whatever the block around says."""
    before = getattr(_MODE, "native", False)
    _MODE.native = native
    try:
        yield
    finally:
        _MODE.native = before


def for_callers(dispatcher: Any) -> contextlib.AbstractContextManager[None]:
    """The mode of a compile of ``dispatcher`` for compiled callers: native only, unless it
    is declared ``njit(python=True)`` (Python calls it in every run too)."""
    return native_only(not getattr(dispatcher, "python", False))


def is_native_only() -> bool:
    """Whether compiles on this thread are for compiled callers only (:func:`native_only`)."""
    return bool(getattr(_MODE, "native", False))


def _native(cres: Any) -> int:
    """The address of a compiled overload's native function (numba's calling convention)."""
    address = int(cres.library.get_pointer_to_function(cres.fndesc.mangled_name))
    if not address:
        raise RuntimeError(f"no native code for {cres.fndesc.qualname}")
    return address


def symbol(dispatcher: Any, cres: Any) -> str:
    """The symbol of ``dispatcher``'s overload ``cres``: its module, name and signature."""
    func = dispatcher.py_func
    text = f"{func.__module__}:{func.__qualname__}:{cres.signature}"
    return "dvqp.kernel." + hashlib.sha256(text.encode()).hexdigest()[:24]


def expose(dispatcher: Any, cres: Any) -> str:
    """Make the overload ``cres`` of the separate kernel ``dispatcher`` callable by its symbol
    (once a process); have numba lower a compiled call to it as a call of that symbol."""
    name = symbol(dispatcher, cres)
    if name not in _EXPOSED:
        _EXPOSED[name] = _native(cres)
        llvm.add_symbol(name, _EXPOSED[name])
    func = dispatcher.py_func
    need: Need = (func.__module__, func.__qualname__, tuple(cres.signature.args), name)
    selector = OverloadSelector()  # replaces numba's, which links the kernel's library in
    call = _symbol_call(name, cres.fndesc, need)
    selector.append(call, call.signature)
    dispatcher.targetctx._defns[cres.entry_point] = selector
    return name


def _symbol_call(name: str, fndesc: Any, need: Need) -> Callable[..., Any]:
    """numba's lowering of a call to a compiled function (``imputils.user_function``), calling
    the symbol ``name`` and linking nothing; the library being compiled records ``need``."""

    def call(context: Any, builder: Any, sig: Any, args: Any) -> Any:
        fnty = context.call_conv.get_function_type(fndesc.restype, fndesc.argtypes)
        function = cgutils.get_or_insert_function(builder.module, fnty, name)
        context.call_conv.decorate_function(
            function, fndesc.args, fndesc.argtypes, noalias=fndesc.noalias
        )
        status, value = context.call_conv.call_function(
            builder, function, fndesc.restype, fndesc.argtypes, args
        )
        with cgutils.if_unlikely(builder, status.is_error):
            context.call_conv.return_status_propagate(builder, status)
        record(context.active_code_library, [need])
        value = fix_returning_optional(context, builder, sig, status, value)
        return impl_ret_new_ref(context, builder, fndesc.restype, value)

    call.signature = fndesc.argtypes  # type: ignore[attr-defined]
    call.libs = ()  # type: ignore[attr-defined]
    return call


def record(library: Any, needs: Iterable[Need]) -> None:
    """Note that ``library``'s code calls the symbols of ``needs``."""
    found = getattr(library, "_dvqp_needs", None)
    if found is None:
        found = library._dvqp_needs = set()
    found.update(needs)


def need(item: Any) -> Need:
    """``item`` as a :data:`Need` read back from a cache entry (TypeError, ValueError if it is
    not one)."""
    module, name, args, name_of_symbol = item
    if not (isinstance(module, str) and isinstance(name, str) and isinstance(name_of_symbol, str)):
        raise TypeError("not a kernel's symbol")
    return module, name, tuple(args), name_of_symbol


def needed_by(library: Any) -> list[Need]:
    """Every symbol ``library``'s machine code calls: its own calls and those of the libraries
    linked into it, sorted."""
    found: set[Need] = set()
    seen: set[int] = set()
    stack = [library]
    while stack:
        lib = stack.pop()
        if id(lib) in seen:
            continue
        seen.add(id(lib))
        found.update(getattr(lib, "_dvqp_needs", ()))
        stack.extend(getattr(lib, "_linking_libraries", ()))
    return sorted(found, key=lambda need: need[3])


def provide(needs: Iterable[Need]) -> bool:
    """Compile or load each kernel ``needs`` names, so that its symbol is known; False if one
    is gone or its signature is no longer the one recorded (the entry's code would call the
    wrong code: it must be compiled anew)."""
    for module, name, args, expected in needs:
        try:
            dispatcher = getattr(importlib.import_module(module), name)
            with for_callers(dispatcher):
                dispatcher.compile(args)
            cres = dispatcher.overloads[tuple(args)]
        except Exception:  # gone, renamed, no longer compiles: the entry is stale
            return False
        if not getattr(dispatcher, "separate", False) or symbol(dispatcher, cres) != expected:
            return False
        if expected not in _EXPOSED:  # compiled before it became separate: not exposed
            return False
    return True


def address_of(dispatcher: Any, argtypes: tuple[Any, ...]) -> int:
    """Compile (or load) ``dispatcher`` for ``argtypes`` and return its native function's
    address, for :func:`indirect` calls."""
    with for_callers(dispatcher):
        dispatcher.compile(tuple(argtypes))
    return _native(dispatcher.overloads[tuple(argtypes)])


def indirect(restype: Any, argtypes: tuple[Any, ...]) -> Any:
    """An intrinsic ``call(address, *args)`` calling the native function at ``address``
    (int64), compiled (:func:`address_of`) for ``argtypes`` and returning ``restype``.

    Each argument is converted to its type in ``argtypes`` at the call; a ``None`` there
    takes the argument's own type (a struct whose type is made at run time): the address
    must then be of the kernel compiled for that very type.
    """
    params = ", ".join(f"a{i}" for i in range(len(argtypes)))
    source = f"def call(typingctx, address, {params}):\n    return _type(address, ({params},))\n"

    def _type(address: Any, args: tuple[Any, ...]) -> Any:
        if not isinstance(address, types.Integer):
            return None
        argtys = tuple(
            types.unliteral(a) if t is None else t for a, t in zip(args, argtypes, strict=True)
        )

        def codegen(context: Any, builder: Any, sig: Any, values: Any) -> Any:
            fnty = context.call_conv.get_function_type(restype, argtys)
            function = builder.inttoptr(values[0], fnty.as_pointer())
            status, value = context.call_conv.call_function(
                builder, function, restype, argtys, values[1:]
            )
            with cgutils.if_unlikely(builder, status.is_error):
                context.call_conv.return_status_propagate(builder, status)
            return impl_ret_new_ref(context, builder, restype, value)

        return signature(restype, types.int64, *argtys), codegen

    namespace: dict[str, Any] = {}
    exec(source, {"_type": _type}, namespace)  # an intrinsic needs its arguments named
    return intrinsic(namespace["call"])


@global_compiler_lock
def ir_functions(
    name: str, define: Callable[[ir.Module], None], names: Iterable[str]
) -> tuple[Any, list[int]]:
    """Compile the functions ``define`` writes in LLVM IR into a code library of their own
    (no numba typing, nothing cached: a few milliseconds once a process) and return the
    library, which must be kept alive while they may run, and the addresses of ``names``.

    The numba runtime is initialised first, so that its ``NRT_*`` functions are symbols the
    module may call; numba's compile lock is held, as its code libraries need."""
    context = cpu_target.target_context
    rtsys.initialize(context)
    library = context.codegen().create_library(name)
    module = library.create_ir_module(name)
    define(module)
    library.add_ir_module(module)
    library.finalize()
    return library, [library.get_pointer_to_function(n) for n in names]
