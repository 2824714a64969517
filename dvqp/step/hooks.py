"""Parts of your own in a compiled run: called between the compiled stages, on the same state.

A task, term, limit or shape that is not one of dvqp's own classes gets its rows here, after
dvqp's parts have written theirs: its compiled kernel if it brings one (``kernel(plan)``), else
its NumPy method on a read-only :class:`~dvqp.KinematicState` view of the step's buffers. Its
rows are reserved once, sized at the run's start; a NumPy method must then return as many rows
at every state (a constraint may return fewer: the rest do not apply).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from dvqp.errors import ParameterError
from dvqp.geometry.measure import user_rows
from dvqp.geometry.shapes import Shape
from dvqp.kinematics.state import KinematicState
from dvqp.limits import Bounds, Constraint, Limit, VelocityDamper
from dvqp.limits.damper import DamperArrays
from dvqp.objective.term import ObjectiveTerm
from dvqp.tasks.task import Task
from dvqp.workspace import Kernel, Slot, StepPlan

Hook = Callable[[], None]


class Hooks:
    """The parts of your own of one run on ``plan``, registered while the step is laid out; a
    NumPy part is called once at the ``start`` state, with the run's step ``dt`` (s), to learn
    its number of rows."""

    def __init__(self, plan: StepPlan, start: KinematicState, dt: float) -> None:
        self.plan, self.start, self.dt = plan, start, dt
        self.view = KinematicState.view(plan.state, plan.radius, plan.k, plan.names)
        self.measured: list[Hook] = []
        self.assessed: list[Hook] = []
        self.prepared: list[Hook] = []
        self.soft = False
        self._pending: list[tuple[list[Hook], Callable[[], Hook]]] = []
        self.describes: dict[int, Callable[[], tuple[str, ...]]] = {}
        self.constraints: dict[int, tuple[Slot, Slot]] = {}
        """The rows of ``G``, ``h`` of each limit of your own (by ``id``)."""

    @property
    def active(self) -> bool:
        """Whether any part of your own is in the run."""
        return bool(self.measured or self.assessed or self.prepared or self._pending)

    def _later(self, stage: list[Hook], make: Callable[[], Hook]) -> None:
        """Make the hook once the plan is finalised (its slots have arrays then)."""
        self._pending.append((stage, make))

    def _kernel(self, stage: list[Hook], kernel: Kernel) -> None:
        self._later(stage, lambda: self.plan.bind(kernel))

    def task(self, task: Task) -> None:
        """A task of your own: a soft cost, or hard rows of ``A``, ``b`` (a kernel's or its
        NumPy ``compute``'s)."""
        if not task.hard:
            self.soft = True
            return self._later(self.prepared, lambda: self._soft(task))
        kernel = task.kernel(self.plan)
        if kernel is not None:
            return self._kernel(self.prepared, kernel)
        count = task.compute(self.start, np.zeros(4), self.dt).rows
        A, b = self.plan.task_rows(count)
        return self._later(self.prepared, lambda: self._hard(task, A, b))

    def term(self, term: ObjectiveTerm) -> None:
        """An objective term of your own: a kernel, or its NumPy ``evaluate``."""
        kernel = term.kernel(self.plan)
        if kernel is not None:
            return self._kernel(self.assessed, kernel)
        return self._later(self.assessed, lambda: self._term(term))

    def damper(self, limit: VelocityDamper) -> tuple[int, int, object, tuple[str, ...]]:
        """A damper of your own: ``(first row, count, safe value, labels)`` of its distances."""
        before = self.plan.rows("dampers")
        kernel = limit.kernel(self.plan)
        if kernel is not None:
            self._kernel(self.assessed, kernel)
            count = self.plan.rows("dampers") - before
            return before, count, limit.safe, limit.labels(self.plan.names)
        found = limit.distances(self.start)
        count = int(np.asarray(found.value).shape[0])
        slots = self.plan.damper_rows(count)
        self._later(self.assessed, lambda: self._distances(limit, slots, count))
        labels = found.describe() if found.describe is not None else limit.labels(self.plan.names)
        return before, count, found.safe, labels

    def limit(self, limit: Limit) -> None:
        """Any other limit of your own: a kernel, or its NumPy ``compute``."""
        kernel = limit.kernel(self.plan)
        if kernel is not None:
            return self._kernel(self.prepared, kernel)
        rows = limit.compute(self.start, self.dt)
        if isinstance(rows, Bounds):
            return self._later(self.prepared, lambda: self._bounds(limit))
        if not isinstance(rows, Constraint):
            raise ParameterError(limit.name, "compute must return a Constraint or Bounds")
        G, h = self.plan.constraint_rows(rows.rows)
        self.constraints[id(limit)] = G, h
        return self._later(self.prepared, lambda: self._rows(limit, G, h))

    def finalize(
        self,
        shapes: Sequence[Shape],
        compiled: np.ndarray,
        params: DamperArrays,
        damper_values: int,
    ) -> None:
        """Make every hook (the plan is finalised) and the one of shapes of your own (not
        ``compiled``)."""
        self._params, self._damper_values = params, damper_values
        for stage, make in self._pending:
            stage.append(make())
        self._pending.clear()
        if not np.all(compiled):  # shapes of your own
            plan = self.plan
            self.measured.append(
                lambda: user_rows(shapes, compiled, plan.state.guarded, plan.period, plan.proximity)
            )

    # -- the hooks ------------------------------------------------------------------------

    def _hard(self, task: Task, A: Slot, b: Slot) -> Hook:
        plan, rows_A, rows_b = self.plan, self.plan.view(A), self.plan.view(b)

        def hook() -> None:
            rows = task.compute(self.view, plan.command, plan.dt[0])
            _fits(task.name, rows.rows, rows_b.shape[0], exact=True)
            rows_A[:], rows_b[:] = rows.jacobian, rows.velocity

        return hook

    def _soft(self, task: Task) -> Hook:
        plan = self.plan
        assert plan.qp is not None

        def hook() -> None:
            H, c = task.compute(self.view, plan.command, plan.dt[0]).objective()
            plan.qp.P[:] += H  # type: ignore[union-attr]
            plan.qp.cost[:] += c  # type: ignore[union-attr]

        return hook

    def _term(self, term: ObjectiveTerm) -> Hook:
        plan = self.plan

        def hook() -> None:
            found = term.evaluate(self.view)
            plan.objective_value[0] += found.value
            plan.objective_gradient[:] += found.gradient

        return hook

    def _distances(self, limit: VelocityDamper, slots: tuple[Slot, ...], count: int) -> Hook:
        plan = self.plan
        distance, gradient, usable = (plan.view(s) for s in slots)
        rows = slice(slots[0].start, slots[0].stop)
        assert plan.checks is not None
        safe, verified = self._params.safe[rows], plan.checks.safe
        at = slice(self._damper_values + rows.start, self._damper_values + rows.stop)

        def hook() -> None:
            found = limit.distances(self.view)
            _fits(limit.name, np.asarray(found.value).shape[0], count, exact=True)
            distance[:], gradient[:] = found.value, found.gradient
            usable[:] = True if found.usable is None else found.usable
            safe[:] = verified[at] = found.safe
            if found.describe is not None:
                self.describes[id(limit)] = found.describe

        return hook

    def _rows(self, limit: Limit, G: Slot, h: Slot) -> Hook:
        plan = self.plan
        rows_G, rows_h = plan.view(G), plan.view(h)

        def hook() -> None:
            found = limit.compute(self.view, plan.dt[0])
            assert isinstance(found, Constraint)
            p = found.rows
            _fits(limit.name, p, rows_h.shape[0], exact=False)
            rows_G[:p], rows_h[:p] = found.G, found.h
            rows_G[p:], rows_h[p:] = 0.0, np.inf
            if found.describe is not None:
                self.describes[id(limit)] = _padded(found.describe, rows_h.shape[0])

        return hook

    def _bounds(self, limit: Limit) -> Hook:
        plan = self.plan

        def hook() -> None:
            found = limit.compute(self.view, plan.dt[0])
            assert isinstance(found, Bounds)
            np.maximum(plan.lb, found.lb, out=plan.lb)
            np.minimum(plan.ub, found.ub, out=plan.ub)

        return hook


def _fits(name: str, got: int, room: int, *, exact: bool) -> None:
    """A part of your own returned ``got`` rows where ``room`` were reserved at the start."""
    if got > room or (exact and got != room):
        raise ParameterError(
            name,
            f"returned {got} rows at this state but {room} at the start "
            "of the run: the number of rows must not change",
        )


def _padded(describe: Callable[[], tuple[str, ...]], count: int) -> Callable[[], tuple[str, ...]]:
    """``describe``'s labels, numbered up to ``count`` rows."""
    return lambda: (*(names := describe()), *(f"row{i}" for i in range(len(names), count)))
