"""What the command line wraps around a run: :func:`check_size` (refuse a run too big for the
memory, announce a long one), :class:`ProgressBar`, :func:`interruptible` (Ctrl-C and
``SIGTERM`` a clean stop) and :func:`warnings_summed_up` (the numerical code's warnings in one
line).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
import time
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TextIO

from dvqp._inputs import MEMORY_SHARE, physical_memory
from dvqp.errors import SceneError, one_line
from dvqp.motion.jog import jog_step_count

if TYPE_CHECKING:
    from dvqp.kinematics.robot import Robot
    from dvqp.scenes.scene import Scene

STEP_SECONDS = 1e-4
"""Typical time of one step, s: the estimate's rate. A compiled step with DAQP takes about
25 µs, the slower backends and steps taken by the reference path a few times more."""
LONG_RUN_SECONDS = 120.0
"""Runs estimated to take longer than this are announced before they start, s."""


@dataclass(frozen=True)
class RunEstimate:
    """How big one planned run will be, from its scene alone: ``steps`` (a path's approach to
    its first waypoint not counted), ``seconds`` at :data:`STEP_SECONDS` a step, ``nbytes``
    of its trajectory's arrays, and the ``motion`` it plans, s (``steps × dt``)."""

    steps: int
    seconds: float
    nbytes: int
    motion: float = 0.0

    @classmethod
    def of(cls, scene: Scene) -> RunEstimate:
        """The estimate of one run of ``scene``."""
        if scene.path is None:
            steps = jog_step_count(scene.jog, scene.dt)
        else:
            steps = int(scene.path.step_count(scene.dt)) + 1
        nbytes = steps * bytes_per_step(scene.robot)
        return cls(steps, steps * STEP_SECONDS, nbytes, steps * scene.dt)

    def describe(self, runs: int = 1) -> str:
        """``about 5e+06 steps (14 h of motion in steps of 0.01 s): roughly 8.3 min and
        5.8 GB`` (for ``runs`` runs): what makes a run long is said, so that a slip (a path
        at 1e-6 m/s) is seen before it runs."""
        runs_text = f" in {runs} runs" if runs > 1 else ""
        motion = ""
        if self.motion > 0.0:
            motion = (
                f" ({duration(self.motion)} of motion in steps of {self.motion / self.steps:.3g} s)"
            )
        return (
            f"about {self.steps:.3g} steps{motion}{runs_text}: roughly "
            f"{duration(self.seconds * runs)} and {self.nbytes / 1e9:.2g} GB"
        )


def bytes_per_step(robot: Robot) -> int:
    """The peak memory a step of a run costs, bytes, for ``n`` joints and ``k`` body points.

    The recorder's arrays (``q`` and ``qdot``: 2n numbers, points 3k, tool 4, rail 3, 12
    figures, flags and a status pointer: ``16n + 24k + 178`` bytes), the trajectory's own
    copies (tool, points, ``qddot``, time, tracking error, status text: ``8n + 24k + 104``)
    and the temporaries of unwrapping, ``qddot`` and saving at the peak (``16n + 24k``).
    A test holds it within 20 % of the peak traced while ``dvqp plan`` runs and saves.
    """
    n, k = robot.n, robot.n_points
    return 8 * (5 * n + 9 * k + 35)


class Terminated(KeyboardInterrupt):
    """``SIGTERM`` (what ``timeout``, ``docker stop`` and systemd send), raised where Ctrl-C
    would be, so that it takes the same way out: files being written are removed, finished
    ones stay (exit code 143, ``dvqp: terminated``)."""


STOPS = {signal.SIGINT: KeyboardInterrupt, signal.SIGTERM: Terminated}
"""The signals :func:`interruptible` turns into an exception, and the exception."""


@contextlib.contextmanager
def interruptible() -> Iterator[None]:
    """Ctrl-C (``SIGINT``) raises KeyboardInterrupt here, ``SIGTERM`` :class:`Terminated` (a
    KeyboardInterrupt too): every ``finally`` and ``except BaseException`` runs, so nothing
    half-written is left behind. Forked worker processes end quietly.

    Forked workers (``compare --jobs``) inherit the handler and exit at once (code 130); a
    signal sent to this process alone (``kill -INT``, ``kill -TERM``) is passed on to them.
    A signal's exception that a library turns into an error of its own (llvmlite, when the
    signal lands while numba compiles: ``AttributeError: 'ValueRef' object has no attribute
    '_as_parameter_'``) leaves as the signal's stop, the error chained to it.
    Outside the main thread (where signals are delivered) nothing changes.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    parent = os.getpid()

    def handler(signum: int, frame: object) -> None:
        if os.getpid() != parent:
            os._exit(130)
        for child in multiprocessing.active_children():
            with contextlib.suppress(OSError, TypeError):
                os.kill(child.pid, signum)  # type: ignore[arg-type]
        _PENDING.append(signum)
        raise STOPS[signal.Signals(signum)]

    previous = {signum: signal.signal(signum, handler) for signum in STOPS}
    try:
        yield
    except KeyboardInterrupt:
        raise
    except Exception as exc:
        if _PENDING:  # the stop, raised inside a library that turned it into its own error
            raise STOPS[signal.Signals(_PENDING[-1])] from exc  # (numba compiling: llvmlite)
        raise
    finally:
        for signum, before in previous.items():
            signal.signal(signum, before)
        _PENDING.clear()


_PENDING: list[int] = []
"""Signals :func:`interruptible` received this command (raised at once, and again by
:func:`stop_if_signalled`)."""


def stop_if_signalled() -> None:
    """Raise the stop of a signal :func:`interruptible` already received, again: the handler
    raises where the main thread happens to run Python code, and that may be a finaliser
    (``__del__``, a weakref callback, a C extension's callback), where CPython prints the
    exception and drops it. A command's loops call this at each step (through its
    :class:`ProgressBar`), so a dropped Ctrl-C or ``SIGTERM`` still stops it."""
    if _PENDING:
        raise STOPS[signal.Signals(_PENDING[-1])]


def terminated(exc: BaseException) -> bool:
    """``exc`` is, or was raised because of, :class:`Terminated` (``SIGTERM``)."""
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, Terminated):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__  # type: ignore[assignment]
    return False


@contextlib.contextmanager
def warnings_summed_up() -> Iterator[list[int]]:
    """Keep warnings (NumPy's ``overflow encountered``, a solver's notes) off the terminal.

    The block appends its exit code to the yielded list. After a run (exit 0 or 1) they are
    summed up in one line, ``dvqp: warning: …``; after bad input (exit 2) only the error
    line is printed.
    """
    code: list[int] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        yield code
    if caught and code and code[0] != 2:
        first = caught[0]
        more = f" ({len(caught) - 1} more)" if len(caught) > 1 else ""
        text = one_line(str(first.message))
        print(f"dvqp: warning: {first.category.__name__}: {text}{more}", file=sys.stderr)


def check_size(scenes: Sequence[Scene], runs: int) -> None:
    """Refuse runs whose arrays would not fit in memory; announce those that take long.

    ``runs``: how many times each scene is run. The announcement is one line on stderr,
    ``dvqp: note: <file>: about 8e+06 steps: roughly 1.3 h and 4.4 GB``.

    Raises
    ------
    SceneError
        ``<file>: motion: about 8e+06 steps: roughly … GB, more than … of this machine``.
    """
    memory = physical_memory()
    for scene in scenes:
        estimate = RunEstimate.of(scene)
        if memory and estimate.nbytes > MEMORY_SHARE * memory:
            raise SceneError(
                scene.source,
                "motion",
                f"{estimate.describe()}, more than this machine's "
                f"{memory / 1e9:.2g} GB allow: use a larger dt or a shorter motion",
            )
        if estimate.seconds * runs > LONG_RUN_SECONDS:
            note = f"{one_line(scene.source)}: {estimate.describe(runs)}"
            print(f"dvqp: note: {note}", file=sys.stderr)


def duration(seconds: float) -> str:
    """``42 s``, ``3.5 min``, ``1.3 h``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.2g} min"
    return f"{seconds / 3600:.2g} h"


class ProgressBar:
    """A one-line progress bar of ``width`` characters on ``stream`` (silent when it is not a
    TTY); after a second it also shows the time left, from the rate so far (of this ``total``:
    a new total, e.g. the steps after compiling, starts its own clock)."""

    def __init__(self, stream: TextIO, width: int = 30) -> None:
        self.stream, self.width = stream, width
        self.enabled = bool(getattr(stream, "isatty", lambda: False)())
        self._last, self._total = -1, 0
        self._started, self._first = time.perf_counter(), 0

    def show(self, done: int, total: int, label: str = "") -> None:
        """Draw ``done`` of ``total`` with a label (redrawn at most every 1 %); first, raise a
        stop that a signal asked for and that was dropped (:func:`stop_if_signalled`)."""
        stop_if_signalled()
        if not self.enabled or total <= 0:
            return
        if total != self._total:  # the steps after compiling: a clock of their own
            if self._total:
                self._started, self._first = time.perf_counter(), done
            self._total, self._last = total, -1
        percent = 100 * done // total
        if percent == self._last and done != total:
            return
        self._last = percent
        filled = self.width * done // total
        bar = "#" * filled + "." * (self.width - filled)
        elapsed, counted = time.perf_counter() - self._started, done - self._first
        left = ""
        if counted > 0 and done < total and elapsed > 1.0:
            left = f" {duration(elapsed * (total - done) / counted)} left"
        self.stream.write(f"\r[{bar}] {done}/{total}{left} {label[:40]:<40}")
        self.stream.flush()

    def note(self, text: str) -> None:
        """``text`` on a line of its own above the bar (nothing when silent)."""
        if self.enabled:
            self.close()
            self.stream.write(f"dvqp: {text}\n")
            self.stream.flush()
            self._last = -1

    def close(self) -> None:
        """Erase the bar (if one was drawn)."""
        if self.enabled and self._last >= 0:
            self.stream.write("\r" + " " * (self.width + 80) + "\r")
            self.stream.flush()
