"""Frame chunks kept while numba compiles: reused, chained to the previous allocator, restored."""

from __future__ import annotations

import ctypes
import sys

import pytest

from solvers import frame_chunks
from solvers.frame_chunks import CHUNK, SLOTS, Allocator, State

pytestmark = pytest.mark.skipif(not frame_chunks._usable(), reason="no arena allocator API")


def current() -> tuple[int | None, int | None, int | None]:
    """The arena allocator in place."""
    found = Allocator()
    ctypes.pythonapi.PyObject_GetArenaAllocator(ctypes.byref(found))
    return found.ctx, found.alloc, found.free


def depth(n: int) -> int:
    """Recurse ``n`` frames (crossing frame chunks on the way down and up)."""
    return 0 if n == 0 else 1 + depth(n - 1)


def test_the_previous_allocator_is_back_after_the_block_and_after_an_error() -> None:
    before = current()
    with frame_chunks.kept():
        inside = current()
        with frame_chunks.kept():
            assert current() == inside  # a nested block shares the outermost's
        assert [depth(400) for _ in range(50)] == [400] * 50
    assert inside != before and current() == before
    with pytest.raises(RuntimeError), frame_chunks.kept():
        raise RuntimeError
    assert current() == before


class Previous:
    """A previous allocator made of counting ctypes callbacks, called only by the tests."""

    def __init__(self) -> None:
        self.blocks: dict[int, ctypes.Array[ctypes.c_char]] = {}
        self.allocated: list[int] = []
        self.freed: list[int] = []
        self._alloc = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)(
            self.alloc
        )
        self._free = frame_chunks._FREE(self.free)

    def alloc(self, context: int | None, size: int) -> int:
        block = ctypes.create_string_buffer(size)
        address = ctypes.addressof(block)
        self.blocks[address] = block
        self.allocated.append(size)
        return address

    def free(self, context: int | None, block: int, size: int) -> None:
        self.freed.append(size)
        del self.blocks[block]

    def state(self) -> State:
        state = State()
        state.previous = Allocator(
            None,
            ctypes.cast(self._alloc, ctypes.c_void_p).value,
            ctypes.cast(self._free, ctypes.c_void_p).value,
        )
        return state


def functions() -> tuple[object, object]:
    """The built allocator's alloc and free, callable from Python."""
    with frame_chunks.kept():  # builds them once
        pass
    _, alloc, free = frame_chunks._built
    alloc_type = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t)
    return alloc_type(alloc), frame_chunks._FREE(free)


def test_a_freed_chunk_is_kept_and_handed_back_other_sizes_pass_through() -> None:
    alloc, free = functions()
    previous = Previous()
    state = previous.state()
    context = ctypes.addressof(state)
    block = alloc(context, CHUNK)
    assert previous.allocated == [CHUNK] and block in previous.blocks
    free(context, block, CHUNK)
    assert previous.freed == [] and state.count == 1  # kept, not freed
    assert alloc(context, CHUNK) == block and previous.allocated == [CHUNK]  # reused
    arena = alloc(context, 1 << 20)
    free(context, arena, 1 << 20)
    assert previous.allocated == [CHUNK, 1 << 20] and previous.freed == [1 << 20]
    free(context, block, CHUNK)
    frame_chunks._give_back(state)
    assert previous.freed == [1 << 20, CHUNK] and not previous.blocks  # all given back


def test_no_more_than_slots_chunks_are_kept() -> None:
    alloc, free = functions()
    previous = Previous()
    state = previous.state()
    context = ctypes.addressof(state)
    blocks = [alloc(context, CHUNK) for _ in range(SLOTS + 3)]
    for block in blocks:
        free(context, block, CHUNK)
    assert state.count == SLOTS and previous.freed == [CHUNK] * 3
    frame_chunks._give_back(state)
    assert len(previous.freed) == SLOTS + 3 and not previous.blocks


def test_an_interrupt_after_installing_leaves_a_working_allocator_the_next_block_restores() -> None:

    before = current()
    with frame_chunks.kept():  # built
        pass
    install = frame_chunks._install.__code__

    def trace(frame, event, arg):  # type: ignore[no-untyped-def]
        if frame.f_code is not install:
            return None

        def local(frame, event, arg):  # type: ignore[no-untyped-def]
            if event == "return" and frame_chunks.installed():
                raise KeyboardInterrupt  # as a Ctrl-C handled after the installing call
            return local

        return local

    sys.settrace(trace)
    try:
        with pytest.raises(KeyboardInterrupt), frame_chunks.kept():
            pass
    finally:
        sys.settrace(None)
    assert frame_chunks.installed()  # left in place, its state alive: frames still allocate
    assert [depth(600) for _ in range(20)] == [600] * 20
    with frame_chunks.kept():
        pass
    assert current() == before and frame_chunks._STATE.count == 0
