"""The console's simulation: one scene, one resolver, a held JOG command, stepped on demand.

:class:`ConsoleSession` is shared by the clock thread, which alone calls :meth:`step` and
touches the stepper, and the server, which sets commands, resets and reads snapshots. A step
is the verified step of ``dvqp plan`` (:func:`dvqp.step.advance`), computed outside the lock:
a command or a snapshot never waits for a solver.
"""

from __future__ import annotations

import math
import threading
import time
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.console import protocol
from dvqp.console.recording import Recording, Sample
from dvqp.errors import DvqpError
from dvqp.motion.trajectory import Trajectory
from dvqp.resolution.registry import check_name, make_resolver
from dvqp.resolution.step import Step
from dvqp.scenes.scene import Scene
from dvqp.step import Advance, Stepper, advance


class Ramp:
    """The JOG command spread over ``window`` steps (1: no ramp), as ``plan`` ramps JOG
    segments: the mean of the last ``window`` targets, so a change of velocity becomes a
    linear ramp and the displacement is that of the targets."""

    def __init__(self, window: int) -> None:
        self._ring = np.zeros((max(1, window), 4))
        self._slot = 0

    def __call__(self, target: NDArray[np.float64]) -> NDArray[np.float64]:
        """This step's command, ``target`` held from now on."""
        self._ring[self._slot] = target
        self._slot = (self._slot + 1) % self._ring.shape[0]
        return self._ring.mean(axis=0)  # type: ignore[no-any-return]

    def clear(self) -> None:
        """At rest at once."""
        self._ring[:] = 0.0


class ConsoleSession:
    """A scene driven live by JOG commands.

    Parameters
    ----------
    scene
        The scene: its arm, start, objective, obstacles, limits and ``dt`` (its motion section
        is not used: the operator drives; a ``ramp`` of its ``[motion]`` spreads each change
        of the JOG over that time, as ``plan`` does).
    backend
        ``"pinv"`` or a QP backend name (default ``"daqp"``, as ``dvqp plan``).

    Raises
    ------
    BackendError
        Unknown backend.
    """

    def __init__(self, scene: Scene, backend: str = "daqp") -> None:
        self.scene, self.backend = scene, check_name(backend)
        self.resolver = make_resolver(backend, scene.spec(), scene.solver_options.get(backend))
        self.verify = self.resolver.holds_limits
        self.stepper = Stepper(
            scene.robot, scene.pipe_radius, self.resolver, scene.q0, scene.dt, scene.obstacles
        )
        self.stepper.start(scene.q0)
        self._first = Sample.of(self.stepper)
        self._lock = threading.Lock()
        self._generation = 0
        self._version = self._applied = 0
        self._ramp = Ramp(round(scene.ramp / scene.dt))
        self.reset()
        self.step()  # warm up the solver and the step, so the first live steps are fast
        self.reset()

    def reset(self) -> None:
        """Back to the scene's start, no command, an empty record (warm starts forgotten)."""
        with self._lock:
            self._generation += 1
            self._version += 1
            self._sample = self._first
            self._command, self._velocity = np.zeros(4), np.zeros(4)
            self._ramp.clear()
            self._clamped: str | None = None
            self._step = Step(np.zeros(self.scene.robot.n), True, "optimal", 0.0, 0.0, None)
            self._substeps, self._t, self._seq = 1, 0.0, 0
            self._recording = Recording(self._first, self.scene.dt)
            self._restart = "start"

    def jog(self, velocity: ArrayLike) -> str | None:
        """Hold the tool velocity ``[l̇, ż, ḣ, α̇]`` (clamped); return the clamping note or None."""
        applied, note = protocol.clamp(np.asarray(velocity, dtype=np.float64))
        with self._lock:
            self._command, self._clamped = applied, note
            self._version += 1
        return note

    def stop(self) -> None:
        """Hold the tool still (zero command, reached along the ramp)."""
        self.jog(np.zeros(4))

    def halt(self) -> None:
        """Stop at once, without a ramp, and start the next step from rest."""
        with self._lock:
            self._command, self._velocity, self._clamped = np.zeros(4), np.zeros(4), None
            self._ramp.clear()
            self._version += 1
            self._restart = self._restart or "rest"

    @property
    def command(self) -> NDArray[np.float64]:
        """The velocity in effect (a copy)."""
        with self._lock:
            return self._command.copy()

    @property
    def version(self) -> int:
        """Counts the commands and resets so far."""
        return self._version

    @property
    def applied(self) -> int:
        """The :attr:`version` the last step made was computed with."""
        return self._applied

    def step(self) -> None:
        """Advance one ``dt`` with the command in effect; a reset meanwhile discards it."""
        with self._lock:
            generation, before, version = self._generation, self._sample, self._version
            restart, self._restart = self._restart, ""
            command = self._ramp(self._command)
        started = time.perf_counter()
        self._restarted(restart)
        moved = self._advance(command)
        after = Sample.of(self.stepper)
        took = time.perf_counter() - started
        with self._lock:
            if generation != self._generation:
                return
            self._recording.add(before, moved, after, command, took)
            self._sample, self._step, self._substeps = after, moved.step, moved.substeps
            self._velocity = command
            self._t += self.scene.dt
            self._seq += 1
            self._applied = version

    def _restarted(self, restart: str) -> None:
        """Back at the start (``"start"``), or from rest where the arm is (``"rest"``): warm
        starts forgotten, and what limits that remember motion remember (as ``plan``)."""
        if restart == "start":
            self.stepper.start(self.scene.q0)
        elif restart == "rest":
            for limit in self.resolver.spec.limits:
                limit.reset()
            if self.stepper.solver is not None:
                self.stepper.solver.reset()

    def _advance(self, command: NDArray[np.float64]) -> Advance:
        """One verified step; an error of the step (a singular configuration) fails it."""
        q = self.stepper.state.q.copy()
        try:
            return advance(self.stepper, command, self.scene.dt, verify=self.verify)
        except DvqpError as exc:
            self.stepper.load(q)
            failed = Step(np.zeros_like(q), False, f"failed: {exc}", math.inf, 0.0, None)
            return Advance(failed, 1)

    def snapshot(self) -> dict[str, Any]:
        """The ``state`` message: time, tool, body points, status, clearance, task error, ...

        ``status`` is ``optimal``, ``relaxed`` or ``failed: <why>``; ``min_clearance`` (m)
        and ``task_error`` are null where undefined (no obstacle; a failed step).
        """
        with self._lock:
            sample, step, t, seq = self._sample, self._step, self._t, self._seq
            command, velocity = self._command.copy(), self._velocity.copy()
            clamped, substeps = self._clamped, self._substeps
            recorded = len(self._recording)
        return {
            "type": "state",
            "t": round(t, 6),
            "tool": protocol.rounded(sample.tool),
            "points": protocol.rounded(sample.points),
            "status": step.status,
            "min_clearance": protocol.finite(sample.min_clearance),
            "task_error": protocol.finite(step.task_error, 9),
            "closest": sample.closest,
            "probe_clearance": protocol.finite(sample.probe_clearance),
            "tilt": protocol.finite(sample.tilt),
            "limits_kept": sample.limits_kept,
            "substeps": substeps,
            "command": protocol.rounded(command),
            "velocity": protocol.rounded(velocity),
            "clamped": clamped,
            "seq": seq,
            "recorded_steps": recorded,
        }

    def trajectory(self) -> Trajectory:
        """What was driven since the last reset (at most the last
        :data:`~dvqp.console.recording.MAX_RECORD_SECONDS`), scene text included."""
        with self._lock:
            recording = self._recording.copy()
        return recording.trajectory(
            self.scene.pipe_radius,
            self.backend,
            self.scene.text,
            self.resolver.spec.level_names,
        )
