"""Ctrl-C while numba compiles or loads its cache: taken right after, not in the middle.

An interrupt raised inside numba's compiler (Python code between LLVM calls) can leave it in a
state where the interrupt is swallowed, LLVM objects fail to be destroyed, or the process
crashes at exit. :func:`guard_compilation` (installed on import of :mod:`dvqp.compiled`)
listens to numba's compiler lock, which numba holds while it compiles a function or loads one
from its cache: while the main thread holds it, a SIGINT is held, and delivered again as soon
as the lock is released.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType
from typing import Any

from numba.core import event


class _Holder:
    """Holds SIGINT while ``depth > 0`` (main thread only), re-raises it at depth 0."""

    def __init__(self) -> None:
        self.depth = 0
        self.caught = False
        self.previous: Any = None

    def _hold(self, signum: int, frame: FrameType | None) -> None:
        self.caught = True

    def enter(self) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        if self.depth == 0:
            if signal.getsignal(signal.SIGINT) is None:  # not installed from Python: leave it
                return
            self.caught = False
            self.previous = signal.signal(signal.SIGINT, self._hold)
        self.depth += 1

    def leave(self) -> None:
        if threading.current_thread() is not threading.main_thread() or self.depth == 0:
            return
        self.depth -= 1
        if self.depth == 0:
            signal.signal(signal.SIGINT, self.previous)
            if self.caught:
                self.caught = False
                signal.raise_signal(signal.SIGINT)  # the restored handler takes it now


_HOLDER = _Holder()


class _CompilerLockListener(event.Listener):  # type: ignore[misc]
    """Holds SIGINT while numba's compiler lock is held."""

    def on_start(self, event: event.Event) -> None:
        _HOLDER.enter()

    def on_end(self, event: event.Event) -> None:
        _HOLDER.leave()


_INSTALLED: list[_CompilerLockListener] = []


def guard_compilation() -> None:
    """Hold SIGINT during every numba compilation and cache load (once per process)."""
    if not _INSTALLED:
        listener = _CompilerLockListener()
        event.register("numba:compiler_lock", listener)
        _INSTALLED.append(listener)
