"""How a part joins a run's step: the tables of the compiled pipeline, which each part fills.

A run lays its step out by asking each of its parts, in the spec's order, to join it
(``part.join(step)``, with ``step`` a :class:`StepWiring`). Nothing outside a part tests what it
is: a part of dvqp's own writes itself into the tables its compiled kernel reads (the rows it
owns, its parameters), a part of your own (the bases' default ``join``) hands itself to the
run's hooks, which call its kernel or NumPy method between the compiled stages. A subclass of a
built-in inherits its ``join``, hence its compiled path; one that overrides the built-in's NumPy
method (or brings a kernel) joins as a part of its own (:func:`overrides`).

The tables (``measures``: which damper rows and task rows each compiled kernel writes; the
objective's levels and obstacle coefficients; the joint boxes; the dampers' parameters) become
the pipeline's arrays once every part has joined (:mod:`dvqp.step.build`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from inspect import getattr_static
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.workspace.plan import StepPlan

Array = NDArray[np.float64]
Index = NDArray[np.int64]

MEASURES = (
    "obstacle_start",
    "obstacle_offsets",
    "obstacle_members",
    "heights",
    "chords",
    "tilts",
    "selves",
)
"""The tables of damper rows the compiled kernels write (see
:class:`~dvqp.step.arrays.MeasureArrays`)."""

TASK_TABLES = ("tool", "point", "posture")
"""The compiled task kinds, each a table of the task rows its kernel writes (see
:class:`~dvqp.step.arrays.TaskArrays`)."""


class PartHooks(Protocol):
    """What a run does with a part of your own (:class:`~dvqp.step.hooks.Hooks`)."""

    def task(self, task: Any) -> None: ...

    def term(self, term: Any) -> None: ...

    def damper(self, limit: Any) -> tuple[int, int, object, tuple[str, ...]]: ...

    def limit(self, limit: Any) -> None: ...


@dataclass(frozen=True)
class DamperBlock:
    """Damper rows ``[start, start + count)`` of ``limit``: their safe values and labels."""

    limit: Any
    start: int
    count: int
    safe: object
    labels: tuple[str, ...]


def overrides(part: object, base: type, *names: str) -> bool:
    """Whether ``part`` replaces any of ``base``'s methods ``names`` (a subclass of a built-in
    that computes its own rows, which then joins as a part of your own): the member ``part``
    finds under each name (:func:`inspect.getattr_static`, not bound) is not ``base``'s."""
    return any(getattr_static(part, name) is not getattr_static(base, name) for name in names)


class StepWiring:
    """The tables a run's parts write themselves into, on ``plan`` (n joints, k body points),
    and the ``hooks`` of the parts of your own.

    Attributes
    ----------
    plan : StepPlan
        The run's rows: a part reserves its own (``plan.task_rows``, ``plan.damper_rows``, ...).
    hooks : PartHooks
        Where a part of your own goes.
    start : object
        The state the run is laid out at (a :class:`~dvqp.KinematicState`): where a task
        without a target finds its start value.
    shapes : list
        The union of the obstacles the parts measure (``part.measured``, each shape once, in
        order of first use): rows of the compiled measurement.
    measures : dict of str to list
        :data:`MEASURES`: each compiled kernel's rows.
    tasks : dict of str to list
        :data:`TASK_TABLES`: each compiled task's entry (its first row of ``A``, its row count,
        and what its kernel reads), in the order the tasks joined.
    levels, k_height : list
        Each orbital-level term's ``h*`` (m) and ``k²`` (k,) (1/m²).
    q_min, q_max, qd_max : ndarray, shape (n,)
        The joint boxes (rad, rad/s), intersected by every joint limit.
    acceleration : object or None
        The acceleration limit (at most one is compiled: the last to join).
    joint_limit : object or None
        The first joint position limit to join: the joints' positions are then verified
        exactly against ``q_min``, ``q_max`` (its tolerance).
    dampers : list of DamperBlock
        Every damper's rows, in row order.
    """

    def __init__(
        self, plan: StepPlan, hooks: PartHooks, shapes: Iterable[Any], start: Any = None
    ) -> None:
        self.plan, self.hooks, self.start = plan, hooks, start
        self.shapes: list[Any] = list({id(s): s for s in shapes}.values())
        self._rows = {id(shape): row for row, shape in enumerate(self.shapes)}
        self.measures: dict[str, list[Any]] = {key: [] for key in MEASURES}
        self.measures["obstacle_offsets"].append(0)
        self.tasks: dict[str, list[Any]] = {key: [] for key in TASK_TABLES}
        self.levels: list[float] = []
        self.k_height: list[Array] = []
        self._point_coef: list[tuple[Index, Array]] = []
        self._link_coef: list[tuple[Index, Array]] = []
        n = plan.n
        self.q_min, self.q_max = np.full(n, -math.inf), np.full(n, math.inf)
        self.qd_max = np.full(n, math.inf)
        self.acceleration: Any = None
        self.joint_limit: Any = None
        self.dampers: list[DamperBlock] = []
        self._refine: list[tuple[Index, float, float]] = []

    # -- obstacles --------------------------------------------------------------------------

    def rows_of(self, shapes: Iterable[Any]) -> Index:
        """Rows of ``shapes`` in the union of measured obstacles (each must be in it: a part
        names what it measures in ``measured``)."""
        try:
            return np.array([self._rows[id(shape)] for shape in shapes], dtype=np.int64)
        except KeyError as exc:
            raise ParameterError("measured", "a part reads an obstacle it does not name") from exc

    def refine(self, rows: Index, safe: float, reach: float) -> None:
        """Measure obstacles ``rows`` exactly (their links on the real DV image) below
        ``safe`` (m), and within ``reach`` (m) by the broad phase."""
        self._refine.append((rows, float(safe), float(reach)))

    def refinement(self, count: int) -> tuple[Array, Array]:
        """``(refine, far)`` (J,) of the ``count`` obstacles of the union, m (0 where none)."""
        refine, far = np.zeros(count), np.zeros(count)
        for rows, safe, reach in self._refine:
            refine[rows] = np.maximum(refine[rows], safe)
            far[rows] = np.maximum(far[rows], reach)
        return refine, far

    # -- the objective ----------------------------------------------------------------------

    def point_coefficients(self, rows: Index, coef: Array) -> None:
        """Add ``coef`` (len(rows), k) to the obstacle-point penalty's coefficients."""
        self._point_coef.append((rows, coef))

    def link_coefficients(self, rows: Index, coef: Array) -> None:
        """Add ``coef`` (len(rows), k − 1) to the obstacle-link penalty's coefficients."""
        self._link_coef.append((rows, coef))

    def coefficients(self) -> tuple[Array, Array]:
        """``(point_coef (J, k), link_coef (J, k − 1))`` over the union's J obstacles."""
        count, k = len(self.shapes), self.plan.k
        point, link = np.zeros((count, k)), np.zeros((count, k - 1))
        for rows, coef in self._point_coef:
            point[rows] += coef
        for rows, coef in self._link_coef:
            link[rows] += coef
        return point, link

    # -- limits -----------------------------------------------------------------------------

    def damper(self, limit: Any, count: int, labels: tuple[str, ...]) -> int:
        """Reserve ``count`` damper rows for ``limit`` (safe value ``limit.safe``); returns the
        first."""
        start = self.plan.damper_rows(count)[0].start
        self.dampers.append(DamperBlock(limit, start, count, limit.safe, labels))
        return start

    def hooked_damper(self, limit: Any) -> None:
        """A damper of your own: its rows from the hooks."""
        start, count, safe, labels = self.hooks.damper(limit)
        if count:
            self.dampers.append(DamperBlock(limit, start, count, safe, labels))

    def intersect(
        self, q_min: Array | None = None, q_max: Array | None = None, qd_max: Array | None = None
    ) -> None:
        """Intersect the compiled joint boxes with positions ``q_min``, ``q_max`` (rad) or
        speeds ``qd_max`` (rad/s), each (n,)."""
        if q_min is not None:
            self.q_min = np.maximum(self.q_min, q_min)
        if q_max is not None:
            self.q_max = np.minimum(self.q_max, q_max)
        if qd_max is not None:
            self.qd_max = np.minimum(self.qd_max, qd_max)

    def damper_parameters(self) -> Array:
        """Per damper row ``[safe, gain, tolerance, deceleration, reach, angle]``, (6, D)."""
        rows: list[tuple[float, ...]] = []
        for block in self.dampers:
            limit = block.limit
            row = (
                float(limit.gain),
                float(limit.tolerance),
                float(limit.deceleration),
                float(limit.reach),
                float(bool(limit.angular)),
            )
            safe = np.broadcast_to(np.asarray(block.safe, float), (block.count,))
            rows += [(float(s), *row) for s in safe]
        return np.array(rows, dtype=float).reshape(-1, 6).T.copy()
