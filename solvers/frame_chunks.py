"""CPython's frame chunks kept for reuse while numba compiles, instead of mapped and unmapped.

CPython 3.11+ keeps the frames of Python calls in 16 KiB chunks that it maps when a call goes
one frame past the last chunk and unmaps when that call returns (``_PyObject_VirtualAlloc`` /
``_PyObject_VirtualFree``, through the arena allocator). numba's compiler recurses deep and
up and down across those boundaries: a cold ``dvqp plan`` made about 320,000 ``mmap`` and as
many ``munmap`` calls of 16 KiB, about 2 s of system time and page faults, a tenth of it.

:func:`kept` installs, for the time of a compile, an arena allocator that chains to the one in
place and keeps up to :data:`SLOTS` freed chunks to hand back at the next request of that size;
any other size (pymalloc's arenas) goes straight to the previous allocator. On leaving, the
previous allocator is restored and the kept chunks are given back to it. Every block is thus
allocated and freed by the previous allocator, whichever is installed when it is released.

The two functions are built once a process from LLVM IR (a few milliseconds; they call no
Python code), and their state (the previous allocator, the kept chunks) lives in a ctypes
structure passed to them as the allocator's context. CPython calls the arena allocator with
its GIL held; where that is not so (a free-threaded build) or there is no such API (another
interpreter), :func:`kept` does nothing.
"""

from __future__ import annotations

import ctypes
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from llvmlite import ir
from numba.core.compiler_lock import global_compiler_lock

from . import linking

CHUNK = 16384
"""Bytes of the chunks kept: CPython's ``DATA_STACK_CHUNK_SIZE`` (3.11-3.13)."""
SLOTS = 64
"""At most this many chunks (1 MiB) are kept."""


class Allocator(ctypes.Structure):
    """CPython's ``PyObjectArenaAllocator``."""

    _fields_ = [("ctx", ctypes.c_void_p), ("alloc", ctypes.c_void_p), ("free", ctypes.c_void_p)]


class State(ctypes.Structure):
    """The context the functions get: the previous allocator, then the kept chunks."""

    _fields_ = [
        ("previous", Allocator),
        ("count", ctypes.c_int64),
        ("slots", ctypes.c_void_p * SLOTS),
    ]


_FREE = ctypes.PYFUNCTYPE(  # the GIL held through the call, as CPython calls the allocator
    None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t
)
_built: list[Any] = []  # the code library, then the addresses of alloc and free
_depth = 0


def _usable() -> bool:
    """Whether this interpreter has the arena allocator API and a GIL."""
    api = getattr(ctypes, "pythonapi", None)
    gil = getattr(sys, "_is_gil_enabled", lambda: True)()
    return (
        sys.implementation.name == "cpython"
        and gil
        and api is not None
        and hasattr(api, "PyObject_SetArenaAllocator")
    )


_STATE = State()
"""The one context the installed allocator uses: never freed, so that an allocator a Ctrl-C
left installed (a KeyboardInterrupt raised between two calls of :func:`kept`'s bookkeeping)
still works, chaining to the previous one, until the next block puts that one back."""


@contextmanager
def kept() -> Iterator[None]:
    """Keep freed frame chunks for reuse within the block (nested blocks share the outermost's
    allocator); hold numba's compile lock, as a compile does."""
    global _depth
    with global_compiler_lock:
        if _depth or not _usable():
            _depth += 1
            try:
                yield
            finally:
                _depth -= 1
            return
        _install()
        _depth = 1
        try:
            yield
        finally:
            _depth = 0
            _restore()


def installed() -> bool:
    """Whether the chaining allocator is the one in place."""
    current = Allocator()
    ctypes.pythonapi.PyObject_GetArenaAllocator(ctypes.byref(current))
    return bool(_built) and current.alloc == _built[1]


def _install() -> None:
    """Install the chaining allocator over the one in place (CPython copies the structure);
    nothing if it is in place already (left by an interrupted block: :data:`_STATE` still
    holds the allocator before it)."""
    if not _built:
        _build()
    if installed():
        return
    if _STATE.count:  # chunks an interrupted restore kept: to the allocator they came from
        _give_back(_STATE)
    ctypes.pythonapi.PyObject_GetArenaAllocator(ctypes.byref(_STATE.previous))
    mine = Allocator(ctypes.addressof(_STATE), _built[1], _built[2])
    ctypes.pythonapi.PyObject_SetArenaAllocator(ctypes.byref(mine))


def _restore() -> None:
    """Put the previous allocator back and give it the kept chunks (a chunk is taken off the
    list before it is freed: an interruption can keep one, never free one twice)."""
    ctypes.pythonapi.PyObject_SetArenaAllocator(ctypes.byref(_STATE.previous))
    _give_back(_STATE)


def _give_back(state: State) -> None:
    """Free the chunks ``state`` keeps with its previous allocator."""
    free = _FREE(state.previous.free)
    while state.count:
        state.count -= 1
        free(state.previous.ctx, state.slots[state.count], CHUNK)


def _build() -> None:
    """Compile the allocator's two functions."""
    names = ["solvers_chunk_alloc", "solvers_chunk_free"]
    library, (alloc, free) = linking.ir_functions("solvers.frame_chunks", _define, names)
    _built.extend([library, alloc, free])


def _define(module: ir.Module) -> None:
    """``i8* solvers_chunk_alloc(i8* state, i64 size)`` and
    ``void solvers_chunk_free(i8* state, i8* block, i64 size)``."""
    byte = ir.IntType(8).as_pointer()
    word = ir.IntType(64)
    alloc_type = ir.FunctionType(byte, [byte, word])
    free_type = ir.FunctionType(ir.VoidType(), [byte, byte, word])
    state_type = ir.LiteralStructType(
        [ir.LiteralStructType([byte, byte, byte]), word, ir.ArrayType(byte, SLOTS)]
    )
    zero, one = ir.Constant(ir.IntType(32), 0), ir.Constant(ir.IntType(32), 1)

    def fields(builder: ir.IRBuilder, raw: ir.Value) -> tuple[Any, ...]:
        state = builder.bitcast(raw, state_type.as_pointer())
        previous = builder.gep(state, [zero, zero])
        count = builder.gep(state, [zero, one])
        slots = builder.gep(state, [zero, ir.Constant(ir.IntType(32), 2)])
        return previous, count, slots

    def chunk(builder: ir.IRBuilder, size: ir.Value) -> ir.Value:
        return builder.icmp_unsigned("==", size, ir.Constant(word, CHUNK))

    def previous_call(builder: ir.IRBuilder, previous: ir.Value, index: int, kind: Any) -> Any:
        context = builder.load(builder.gep(previous, [zero, zero]))
        field = ir.Constant(ir.IntType(32), index)
        function = builder.bitcast(builder.load(builder.gep(previous, [zero, field])), kind)
        return context, function

    alloc = ir.Function(module, alloc_type, name="solvers_chunk_alloc")
    raw, size = alloc.args
    builder = ir.IRBuilder(alloc.append_basic_block("entry"))
    previous, count, slots = fields(builder, raw)
    held = builder.load(count)
    reuse = builder.and_(chunk(builder, size), builder.icmp_signed(">", held, ir.Constant(word, 0)))
    with builder.if_then(reuse):
        last = builder.sub(held, ir.Constant(word, 1))
        builder.store(last, count)
        builder.ret(builder.load(builder.gep(slots, [ir.Constant(word, 0), last])))
    context, function = previous_call(builder, previous, 1, alloc_type.as_pointer())
    builder.ret(builder.call(function, [context, size]))

    free = ir.Function(module, free_type, name="solvers_chunk_free")
    raw, block, size = free.args
    builder = ir.IRBuilder(free.append_basic_block("entry"))
    previous, count, slots = fields(builder, raw)
    held = builder.load(count)
    room = builder.icmp_signed("<", held, ir.Constant(word, SLOTS))
    keep = builder.and_(
        builder.and_(chunk(builder, size), room),
        builder.icmp_unsigned("!=", block, ir.Constant(byte, None)),
    )
    with builder.if_then(keep):
        builder.store(block, builder.gep(slots, [ir.Constant(word, 0), held]))
        builder.store(builder.add(held, ir.Constant(word, 1)), count)
        builder.ret_void()
    context, function = previous_call(builder, previous, 2, free_type.as_pointer())
    builder.call(function, [context, block, size])
    builder.ret_void()
