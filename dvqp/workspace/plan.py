"""The layout of one run's compiled step: its shared buffers, and which part owns which rows.

A run's parts ask the :class:`StepPlan` for their rows once, before the run: a task for rows of
the hard tasks' ``A Q̇ = b`` (:meth:`StepPlan.task_rows`), a distance limit (a velocity damper)
for distances whose rows of ``G Q̇ ≤ h`` are made from them (:meth:`StepPlan.damper_rows`),
any other limit for rows of ``G``, ``h`` (:meth:`StepPlan.constraint_rows`), a verified limit
for exact values checked after every step (:meth:`StepPlan.verified`). Each gets
:class:`Slot` placeholders; once every part has asked, :meth:`StepPlan.finalize` allocates the
arrays, whose sizes never change during the run: a row that does not apply at some state is
written ``0 · Q̇ ≤ +inf``, so the QP backend is set up once and then only updated.

``G`` holds the damper rows first (row r of ``G`` is distance r), then the other limits' rows.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.errors import ParameterError
from dvqp.workspace.buffers import PairBuffers, ProximityBuffers, StateBuffers
from dvqp.workspace.parts import PartNames

Array = NDArray[np.float64]

BLOCKS = {
    "A": "tasks",
    "b": "tasks",
    "distance": "dampers",
    "gradient": "dampers",
    "usable": "dampers",
    "G": "constraints",
    "h": "constraints",
    "values": "values",
}
"""Each array a :class:`Slot` may name, and the block of rows it belongs to."""


@dataclass(frozen=True)
class Slot:
    """Rows ``[start, stop)`` of one of the plan's arrays (a placeholder until finalised)."""

    array: str
    start: int
    stop: int


@dataclass(frozen=True)
class Kernel:
    """A compiled function of a part and the arrays it reads and writes, bound once.

    Calling it runs ``function(*args)``; ``args`` may hold :class:`Slot` placeholders until
    :meth:`StepPlan.bind` replaces them with views of the finalised arrays.
    """

    function: Callable[..., Any]
    args: tuple[Any, ...]

    def __call__(self) -> None:
        self.function(*self.args)


@dataclass(frozen=True)
class QPBuffers:
    """The step's QP ``min ½ Q̇ᵀ P Q̇ + costᵀ Q̇`` s.t. ``A Q̇ = b``, ``G Q̇ ≤ h``,
    ``lb ≤ Q̇ ≤ ub``: P (n, n), cost (n,), A (m, n), b (m,), G (p, n), h (p,), lb, ub (n,)."""

    P: Array
    cost: Array
    A: Array
    b: Array
    G: Array
    h: Array
    lb: Array
    ub: Array


@dataclass(frozen=True)
class DamperBuffers:
    """The distances the dampers keep, one per damper row: ``distance`` (D,) (m, or the
    distance's unit), ``gradient`` (D, n) ``∂d/∂Q``, ``usable`` (D,) bool (a row applies only
    where its gradient is defined)."""

    distance: Array
    gradient: Array
    usable: NDArray[np.bool_]


@dataclass(frozen=True)
class CheckBuffers:
    """The exact values verified after every step (V,): a step keeps its limits while every
    value stays at or above ``floor − tolerance``, ``floor = min(safe, value at the run's
    start)``; ``excess`` (2,) is ``[floor − value, (floor − value)/tolerance]`` of the worst.
    ``lowest`` (V,) is each value's smallest over the recorded samples (``inf`` before any),
    ``settled`` (V,) the same over the samples before ``row[0]``, the one last written (a
    sample written again replaces its value)."""

    values: Array
    safe: Array
    tolerance: Array
    floor: Array
    excess: Array
    lowest: Array
    settled: Array
    row: NDArray[np.int64]


class StepPlan:
    """Buffers and row layout of one run's compiled step.

    Parameters
    ----------
    n, k
        Joints and body points.
    radius
        Pipe radius, m.
    obstacles
        Obstacles whose proximity every state computes (the union of the run's sets).
    rail
        Whether the arm has a rail point (a guarded point after the tool, and the carriage
        link from it to body point 1).
    names
        The guarded parts' names in labels (default: dvqp's numbering, ``point1``, …).

    Attributes
    ----------
    state, proximity, pairs
        The kinematics, the proximity to the obstacles and the link pairs of the current state.
    dt : ndarray, shape (1,)
        The step, s, updated per step.
    command : ndarray, shape (4,)
        The operator's tool command ``[l̇, ż, ḣ, α̇]`` this step.
    objective_value, objective_gradient : ndarray, shapes (1,), (n,)
        ``w`` and ``∂w/∂Q`` at the current state.
    qp, dampers, checks
        The finalised arrays (None before :meth:`finalize`).
    """

    def __init__(
        self,
        n: int,
        k: int,
        radius: float,
        obstacles: int = 0,
        rail: bool = False,
        names: PartNames | None = None,
    ) -> None:
        self.n, self.k, self.radius, self.rail = n, k, float(radius), bool(rail)
        self.names = PartNames.numbered(k, rail) if names is None else names
        if (self.names.k, self.names.rail) != (k, self.rail):
            raise ParameterError("names", f"not the names of {k} body points (rail: {rail})")
        self.state = StateBuffers.allocate(n, k, rail)
        self.proximity = ProximityBuffers.allocate(obstacles, k, rail)
        self.pairs = PairBuffers.allocate(k, rail)
        self.dt, self.command = np.zeros(1), np.zeros(4)
        self.objective_value, self.objective_gradient = np.zeros(1), np.zeros(n)
        self.lb, self.ub = np.full(n, -np.inf), np.full(n, np.inf)
        self._sizes = dict.fromkeys(("tasks", "dampers", "constraints", "values"), 0)
        self._safe: list[Array] = []
        self._tolerance: list[Array] = []
        self.qp: QPBuffers | None = None
        self.dampers: DamperBuffers | None = None
        self.checks: CheckBuffers | None = None

    @property
    def period(self) -> float:
        """``2πR``, m: the period of l."""
        return 2.0 * np.pi * self.radius

    def _reserve(self, block: str, count: int, *arrays: str) -> tuple[Slot, ...]:
        if self.qp is not None:
            raise ParameterError(block, "rows asked for after the plan was finalised")
        start = self._sizes[block]
        self._sizes[block] = start + int(count)
        return tuple(Slot(a, start, start + int(count)) for a in arrays)

    def rows(self, block: str) -> int:
        """How many rows of ``block`` (``"tasks"``, ``"dampers"``, ``"constraints"``,
        ``"values"``) have been asked for so far."""
        return self._sizes[block]

    def task_rows(self, count: int) -> tuple[Slot, Slot]:
        """``count`` rows of the hard tasks' ``A`` (count, n) and ``b`` (count,)."""
        return self._reserve("tasks", count, "A", "b")  # type: ignore[return-value]

    def damper_rows(self, count: int) -> tuple[Slot, Slot, Slot]:
        """``count`` damper distances: ``distance`` (count,), ``gradient`` (count, n),
        ``usable`` (count,); each becomes a row of ``G``, ``h``."""
        return self._reserve("dampers", count, "distance", "gradient", "usable")  # type: ignore[return-value]

    def constraint_rows(self, count: int) -> tuple[Slot, Slot]:
        """``count`` rows of ``G`` (count, n) and ``h`` (count,) after the damper rows."""
        return self._reserve("constraints", count, "G", "h")  # type: ignore[return-value]

    def verified(self, count: int, safe: ArrayLike, tolerance: ArrayLike) -> Slot:
        """``count`` exact values (checked after every step, see :class:`CheckBuffers`) with
        their safe values and tolerances (scalars or one per value)."""
        (slot,) = self._reserve("values", count, "values")
        for kept, value in ((self._safe, safe), (self._tolerance, tolerance)):
            kept.append(np.broadcast_to(np.asarray(value, dtype=np.float64), (count,)).copy())
        return slot

    def finalize(self) -> None:
        """Allocate the arrays of every row asked for (once; no more rows after it)."""
        if self.qp is not None:
            return
        n, s = self.n, self._sizes
        m, d, p, v = s["tasks"], s["dampers"], s["constraints"], s["values"]
        G, h = np.zeros((d + p, n)), np.full(d + p, np.inf)
        self.qp = QPBuffers(
            np.eye(n), np.zeros(n), np.zeros((m, n)), np.zeros(m), G, h, self.lb, self.ub
        )
        self.dampers = DamperBuffers(np.zeros(d), np.zeros((d, n)), np.zeros(d, dtype=np.bool_))
        joined = lambda parts: np.concatenate(parts) if parts else np.zeros(0)  # noqa: E731
        self.checks = CheckBuffers(
            np.zeros(v),
            joined(self._safe),
            joined(self._tolerance),
            np.zeros(v),
            np.zeros(2),
            np.full(v, np.inf),
            np.full(v, np.inf),
            np.full(1, -1, np.int64),
        )

    def view(self, slot: Slot) -> Array:
        """The rows of the finalised array that ``slot`` names."""
        self.finalize()
        assert self.qp is not None and self.dampers is not None and self.checks is not None
        offset = self._sizes["dampers"] if BLOCKS[slot.array] == "constraints" else 0
        owner = {
            "tasks": self.qp,
            "constraints": self.qp,
            "dampers": self.dampers,
            "values": self.checks,
        }[BLOCKS[slot.array]]
        return getattr(owner, slot.array)[offset + slot.start : offset + slot.stop]  # type: ignore[no-any-return]

    def bind(self, kernel: Kernel) -> Kernel:
        """``kernel`` with its :class:`Slot` arguments replaced by views (finalising the plan)."""
        args = tuple(self.view(a) if isinstance(a, Slot) else a for a in kernel.args)
        return Kernel(kernel.function, args)
