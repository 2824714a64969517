"""One line on stderr while a command compiles (the first run after installing dvqp).

numba compiles a kernel the first time it is called and caches it on disk; later runs load it.
:func:`announced` watches numba's compile events for the length of a command: once compiling has
gone on for :data:`AFTER` seconds, one line says what is happening and about how long it takes,
whether stderr is a terminal or redirected; when the command ends, a second line says how long
compiling took. A command that compiles nothing (everything cached) prints neither.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any, TextIO

from numba.core import event

AFTER = 0.1
"""s: compiling for longer than this is announced (a run with every kernel cached compiles
nothing; a cold one starts compiling about 2 s after the command starts, most of it
importing)."""

ESTIMATES = {"plan": 23, "compare": 29, "export-qps": 23, "bench": 35}
"""s a first run of each command compiles for on the paper scene (a 2-core machine, quiet:
``benchmarks/startup.py``); other commands compile less."""


LOOP_MODULE = "dvqp.motion.follow"
"""The module of a run's step loop, which the run after the first compiles
(:data:`dvqp.motion.follow.COMPILE`)."""
LOOP = 3
"""s the step loop compiles for (``benchmarks/startup.py``'s second runs)."""


class _Watch(event.Listener):  # type: ignore[misc]
    """Counts numba's compile events and their wall time (outermost only). numba compiles
    under its one compiler lock, so the events come one at a time; no lock of its own (a
    forked worker never inherits one held)."""

    def __init__(self) -> None:
        self.depth, self.count, self.busy, self._since = 0, 0, 0.0, 0.0
        self.first = ""
        """The module of the first kernel compiled (outermost)."""

    def on_start(self, ev: Any) -> None:
        if self.depth == 0:
            self._since = time.perf_counter()
            if not self.count:
                dispatcher = ev.data.get("dispatcher")
                self.first = getattr(getattr(dispatcher, "py_func", None), "__module__", "")
        self.depth += 1
        self.count += 1

    def on_end(self, ev: Any) -> None:
        self.depth -= 1
        if self.depth == 0:
            self.busy += time.perf_counter() - self._since

    def elapsed(self) -> float:
        """s spent compiling so far (a read racing an event is off by one event at most)."""
        since, depth, busy = self._since, self.depth, self.busy
        return busy + (time.perf_counter() - since if depth else 0.0)


@contextlib.contextmanager
def announced(command: str, stream: TextIO | None = None) -> Iterator[None]:
    """Announce compiling during the block (``command``: the subcommand, for its estimate)."""
    out = sys.stderr if stream is None else stream
    watch, said = _Watch(), threading.Event()
    estimate = ESTIMATES.get(command)
    about = f"about {estimate} s" if estimate else "a few seconds"
    stop = threading.Event()

    def announce() -> None:
        while not stop.wait(0.1):
            if watch.elapsed() >= AFTER:
                what = (
                    f"the run's step loop: once, the run after the first (about {LOOP} s"
                    if watch.first == LOOP_MODULE
                    else f"the step's kernels: the first run after installing only ({about}"
                )
                print(f"dvqp: compiling {what}; cached for later runs)", file=out, flush=True)
                said.set()
                return

    thread = threading.Thread(target=announce, daemon=True)
    event.register("numba:compile", watch)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        event.unregister("numba:compile", watch)
        if said.is_set():
            print(
                f"dvqp: compiled {watch.count} kernel{'s' * (watch.count != 1)} in "
                f"{watch.busy:.0f} s, cached",
                file=out,
                flush=True,
            )
