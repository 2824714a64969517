"""A simulated run on the compiled step, the reference step taking over where it must."""

from __future__ import annotations

import time

from dvqp.compiled.engine import CompiledStep
from dvqp.errors import SingularConfigurationError
from dvqp.kinematics.state import KinematicState
from dvqp.motion.run import Run


def run_compiled(step: CompiledStep, run: Run) -> None:
    """Simulate ``run`` with ``step`` (the same samples and steps as
    :func:`dvqp.motion.run.run_reference`, to rounding); a step the compiled path hands back
    is taken by the reference :func:`~dvqp.motion.advance.advance` from the same state."""
    record, plan = run.record, step.plan
    step.start(run.q0)
    start: KinematicState | None = None
    n_steps = run.commands.shape[0]
    excess, kept = -float("inf"), True
    started = time.perf_counter()
    for i in range(n_steps + 1):
        s = plan.state
        record.sample_values(i, s.q, s.tool, s.guarded, float(plan.objective_value[0]), excess,
                             kept, step.diagnostics)  # fmt: skip
        if i == n_steps:
            break
        q = s.q.copy()
        xdot = run.command(i, s.tool)
        answer = step.step(xdot, run.dt)
        if answer is not None:
            now = time.perf_counter()
            record.step_values(i, answer, 1, now - started, True)  # type: ignore[arg-type]
            excess, kept = float(step.excess[0]), not step.broken
        else:
            if start is None:
                start = KinematicState.compute(run.robot, run.q0, run.radius)
            state = KinematicState.compute(run.robot, q, run.radius)
            moved = run.advance(state, xdot, start)
            now = time.perf_counter()
            record.step(i, moved, now - started)
            if not step.load(moved.state.q):
                raise SingularConfigurationError("the compiled kinematics found a singular frame")
            if moved.step.success:
                excess, kept = moved.excess.value, not moved.excess.broken
        started = now
        if run.progress is not None:
            run.progress(i + 1, n_steps)
