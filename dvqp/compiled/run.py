"""A simulated run on the compiled step, the reference step taking over where it must."""

from __future__ import annotations

import time

import numpy as np

from dvqp.compiled.engine import CompiledStep
from dvqp.compiled.solve import Answer, finish
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics.state import KinematicState
from dvqp.motion.recorder import TrajectoryRecorder
from dvqp.motion.run import Run


def run_compiled(step: CompiledStep, run: Run) -> None:
    """Simulate ``run`` with ``step`` (the same samples and steps as
    :func:`dvqp.motion.run.run_reference`, to rounding); a step the compiled path hands back
    is taken by the reference :func:`~dvqp.motion.advance.advance` from the same state.

    ``step`` must have been compiled with the run's recorder arrays: its evaluation writes
    each sample.
    """
    record, state = run.record, step.plan.state
    step.index[0] = 0
    step.start(run.q0)
    _first_calls(step, run)  # load (or compile) now what the timed steps call directly
    start: KinematicState | None = None
    saved = np.empty_like(run.q0)
    plain = run.reference is None or run.gain <= 0.0
    started = time.perf_counter()
    for i in range(run.commands.shape[0]):
        np.copyto(saved, state.q)
        xdot = run.commands[i] if plain else run.command(i, state.tool)
        step.index[0] = i + 1
        answer = step.step(xdot, run.dt)
        if answer is None:
            start = _reference_step(step, run, saved, xdot, start, i, started)
        else:
            _record(record, i, answer, time.perf_counter() - started)
        started = time.perf_counter()
        if run.progress is not None:
            run.progress(i + 1, run.commands.shape[0])


def _first_calls(step: CompiledStep, run: Run) -> None:
    """Compile (or load) now the kernels the step calls directly: the integration and the
    backend layer's solution check (through one solve of the start's QP, whose warm start is
    then forgotten)."""
    if run.commands.shape[0] == 0:
        return
    plan = step.plan
    np.copyto(plan.command, run.commands[0])
    plan.dt[0] = run.dt
    status = step.prepare()
    answer = step.solver.solve(status)
    st = plan.stacked
    x = np.zeros(plan.n) if answer is None else answer.qdot
    finish(st["A"], st["b"], x, np.zeros(plan.n), run.dt, np.zeros(2))
    step.solver.reset()


def _record(record: TrajectoryRecorder, i: int, answer: Answer, elapsed: float) -> None:
    """Step i as the compiled path took it (its end state is recorded by the evaluation)."""
    a = record.arrays
    a["qdot"][i] = answer.qdot
    a["solve_time"][i], a["solver_time"][i], a["step_time"][i] = (
        answer.solve_time, answer.solver_time, elapsed,
    )  # fmt: skip
    a["task_error"][i] = answer.task_error
    a["iterations"][i] = -1 if answer.iterations is None else answer.iterations
    a["success"][i] = a["compiled"][i] = True
    record.status[i] = answer.status


def _reference_step(
    step: CompiledStep, run: Run, q: np.ndarray, xdot: np.ndarray,
    start: KinematicState | None, i: int, started: float,
) -> KinematicState:  # fmt: skip
    """Step i on the reference path from ``q``; the compiled buffers then load its end."""
    if start is None:
        start = KinematicState.compute(run.robot, run.q0, run.radius)
    moved = run.advance(KinematicState.compute(run.robot, q, run.radius), xdot, start)
    run.record.step(i, moved, time.perf_counter() - started)
    if not step.load(moved.state.q):
        raise SingularConfigurationError("the compiled kinematics found a singular frame")
    return start
