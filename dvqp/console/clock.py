"""Real-time stepping: a thread that advances a session every ``dt`` of wall time while a
client is connected, and measures the rate it achieves."""

from __future__ import annotations

import sys
import threading
import time
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from dvqp.console.session import ConsoleSession
from dvqp.errors import one_line

MAX_LAG = 0.1
"""Largest lag behind real time (s) made up by stepping faster; more is dropped."""


@dataclass
class RateStats:
    """What the clock achieved while running: the ``steps`` made, the ``wall`` time spent (s),
    the simulated time ``dropped`` to stay in real time (s), and of the last steps their wall
    time (``step_times``, s) and when they ended (``stamps``, ``time.perf_counter``, s)."""

    steps: int = 0
    wall: float = 0.0
    dropped: float = 0.0
    step_times: deque[float] = field(default_factory=lambda: deque(maxlen=4096))
    stamps: deque[float] = field(default_factory=lambda: deque(maxlen=200))

    def realtime(self, dt: float) -> float:
        """Simulated time over wall time (1.0: real time); 0 before the first step."""
        return self.steps * dt / self.wall if self.wall > 0 else 0.0

    def recent(self, dt: float) -> float | None:
        """Simulated over wall time across the last steps (None: too few, or paused)."""
        stamps = list(self.stamps)
        if len(stamps) < 10 or stamps[-1] <= stamps[0]:
            return None
        return (len(stamps) - 1) * dt / (stamps[-1] - stamps[0])

    def summary(self, dt: float) -> dict[str, float]:
        """Rate, steps, wall time, dropped time and step-time percentiles (ms)."""
        times = np.array(self.step_times) * 1e3 if self.step_times else np.zeros(1)
        return {
            "realtime": self.realtime(dt),
            "steps": self.steps,
            "wall_s": self.wall,
            "dropped_s": self.dropped,
            "step_ms_median": float(np.median(times)),
            "step_ms_p95": float(np.percentile(times, 95)),
            "step_ms_max": float(times.max()),
        }


class RealTimeClock:
    """Steps ``session`` at its scene's ``dt`` in a daemon thread, from :meth:`resume` to
    :meth:`pause`: a late step is made at once, a lag of more than :data:`MAX_LAG` dropped."""

    def __init__(self, session: ConsoleSession) -> None:
        self.session, self.dt = session, session.scene.dt
        self.stats = RateStats()
        self._running = threading.Event()
        self._closing = threading.Event()
        self._reported: set[str] = set()
        self._thread = threading.Thread(target=self._loop, name="dvqp-console-clock", daemon=True)

    def start(self) -> None:
        """Start the thread (paused)."""
        self._thread.start()

    def resume(self) -> None:
        """Step in real time from now."""
        self._running.set()

    def pause(self) -> None:
        """Make no more steps: the arm holds still."""
        self._running.clear()

    @property
    def running(self) -> bool:
        """Stepping now."""
        return self._running.is_set()

    def close(self) -> None:
        """Stop the thread and wait for it."""
        self._closing.set()
        self._running.set()
        if self._thread.is_alive():
            self._thread.join(timeout=5.0)

    def _loop(self) -> None:
        while not self._closing.is_set():
            if self._running.wait(timeout=0.1):
                self._run()

    def _run(self) -> None:
        """Step until paused or closed, each step due ``dt`` after the previous one."""
        began = deadline = time.perf_counter()
        wall = self.stats.wall
        while self._running.is_set() and not self._closing.is_set():
            self._step()
            deadline += self.dt
            now = time.perf_counter()
            self.stats.steps += 1
            self.stats.wall = wall + now - began
            self.stats.stamps.append(now)
            if deadline > now:
                self._closing.wait(deadline - now)
            elif now - deadline > MAX_LAG:
                self.stats.dropped += now - deadline
                deadline = now
        self.stats.stamps.clear()

    def _step(self) -> None:
        """One step, timed; the thread survives whatever a step raises (reported once)."""
        started = time.perf_counter()
        try:
            self.session.step()
        except Exception as exc:  # the clock must keep the console alive
            self.session.stop()
            message = f"dvqp: console: step failed: {type(exc).__name__}: {one_line(str(exc))}"
            if message not in self._reported:
                self._reported.add(message)
                print(message, file=sys.stderr)
        self.stats.step_times.append(time.perf_counter() - started)
