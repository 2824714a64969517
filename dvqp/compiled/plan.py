"""The fixed layout of a run's compiled step: preallocated buffers and the kernels that fill them.

A run compiles its :class:`~dvqp.resolution.spec.StepSpec` once into a :class:`StepPlan`. Every
task, objective term, limit and obstacle shape that can be compiled provides a
:class:`Kernel`: a numba-compiled function and the arrays it reads and writes, all allocated
here once. Nothing is allocated, stacked or validated per step: the engine only calls the bound
kernels in order, then the QP backend on the same arrays.

The QP's structure is fixed for the whole run. A limit asks for its rows once
(:meth:`StepPlan.constraint_rows`); a row that does not apply at some state (a pair far from its
obstacle) is written as ``G = 0, h = +inf`` instead of disappearing, so the backend is set up
once and keeps its warm start.

Arrays that are only known once every part has asked for its rows (the stacked ``G``, ``h`` and
the verification values) are handed out as :class:`Slot` placeholders, replaced by views of the
final arrays when the plan is finalised (:meth:`StepPlan.bind`).

Per state the engine runs, in order: kinematics (:attr:`StepPlan.state`), geometry (the shapes'
proximity kernels and the self-collision pairs, once per state), the objective terms
(accumulating into :attr:`StepPlan.objective_value` and :attr:`StepPlan.objective_gradient`,
zeroed first), and the verification values. Per step: the task rows (``A``, ``b``), then the
limits' rows (``G``, ``h``) and bounds (intersected into ``lb``, ``ub``, reset to ``∓inf``
first). ``dt`` (s) and the tool command are one-element and (4,) arrays updated per step.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from dvqp.compiled import ownership
from dvqp.compiled.buffers import (
    Kernel,
    ProximityBuffers,
    SelfPairBuffers,
    Slot,
    StateBuffers,
)
from dvqp.errors import ParameterError

if TYPE_CHECKING:
    from dvqp.geometry.obstacle import ObstacleSet

Array = NDArray[np.float64]

__all__ = ["Kernel", "ProximityBuffers", "SelfPairBuffers", "Slot", "StateBuffers", "StepPlan"]


@dataclass
class Verification:
    """One verified limit's slice of the verification values."""

    limit: Any
    slot: Slot
    safe: Array
    tolerance: float


@dataclass
class StepPlan:
    """Buffers and kernels of one run's compiled step (see the module docstring).

    Parameters
    ----------
    n, k
        Joints and body points.
    radius
        Pipe radius, m.
    """

    n: int
    k: int
    radius: float
    state: StateBuffers = field(init=False)
    dt: Array = field(init=False)
    command: Array = field(init=False)
    objective_value: Array = field(init=False)
    objective_gradient: Array = field(init=False)
    lb: Array = field(init=False)
    ub: Array = field(init=False)
    geometry: list[Kernel] = field(default_factory=list, init=False)
    _sizes: dict[str, int] = field(default_factory=dict, init=False)
    _proximity: dict[int, tuple[Any, ProximityBuffers]] = field(default_factory=dict, init=False)
    _pairs: SelfPairBuffers | None = field(default=None, init=False)
    verifications: list[Verification] = field(default_factory=list, init=False)
    stacked: dict[str, Array] = field(default_factory=dict, init=False)

    def __post_init__(self) -> None:
        self.state = StateBuffers.allocate(self.n, self.k)
        self.dt = np.zeros(1)
        self.command = np.zeros(4)
        self.objective_value = np.zeros(1)
        self.objective_gradient = np.zeros(self.n)
        self.lb = np.full(self.n, -np.inf)
        self.ub = np.full(self.n, np.inf)

    @property
    def period(self) -> float:
        """``2πR``, m: the period of l."""
        return 2.0 * np.pi * self.radius

    def _slot(self, array: str, count: int) -> Slot:
        if self.stacked:
            raise ParameterError(array, "rows asked for after the plan was finalised")
        start = self._sizes.get(array, 0)
        self._sizes[array] = start + count
        return Slot(array, start, start + count)

    def constraint_rows(self, count: int) -> tuple[Slot, Slot]:
        """``count`` fixed rows of ``G`` (shape (count, n)) and ``h`` (count,)."""
        return self._slot("G", count), self._slot("h", count)

    def task_rows(self, count: int) -> tuple[Slot, Slot]:
        """``count`` rows of the hard tasks' ``A`` (count, n) and ``b`` (count,)."""
        return self._slot("A", count), self._slot("b", count)

    def verified(self, limit: Any, count: int, safe: Array | float, tolerance: float) -> Slot:
        """``count`` verification values of ``limit`` (its exact quantity at a state, e.g.
        clearances, m) with their safe values: a step keeps the limit while every value stays
        at or above ``min(safe, value at the run's start) − tolerance``."""
        slot = self._slot("values", count)
        safe_arr = np.broadcast_to(np.asarray(safe, dtype=np.float64), (count,)).copy()
        self.verifications.append(Verification(limit, slot, safe_arr, float(tolerance)))
        return slot

    def proximity(self, obstacles: ObstacleSet) -> ProximityBuffers | None:
        """The proximity buffers of ``obstacles``, computed once per state (the shapes'
        kernels are added to :attr:`geometry` the first time); None if a shape has no kernel."""
        found = self._proximity.get(id(obstacles))
        if found is not None:
            return found[1]
        buffers = ProximityBuffers.allocate(len(obstacles), self.k)
        kernels = []
        for cls, shapes, indices in obstacles.groups():
            make = ownership.own_kernel(cls, "kernel")
            index = np.asarray(indices, dtype=np.int64)
            kernel = None if make is None else make(shapes, index, self, buffers)
            if kernel is None:
                return None
            kernels.append(kernel)
        self.geometry.extend(kernels)
        self._proximity[id(obstacles)] = (obstacles, buffers)
        return buffers

    def self_pairs(self) -> SelfPairBuffers:
        """The self-collision pair geometry, computed once per state."""
        if self._pairs is None:
            from dvqp.limits.self_collision import pairs_kernel

            self._pairs, kernel = pairs_kernel(self)
            self.geometry.append(kernel)
        return self._pairs

    def finalize(self) -> None:
        """Allocate the stacked arrays (once; no more rows may be asked for after it)."""
        if not self.stacked:
            self._allocate()

    def bind(self, kernel: Kernel) -> Kernel:
        """``kernel`` with its :class:`Slot` arguments replaced by views of the stacked arrays
        (finalising the plan on the first call)."""
        self.finalize()
        args = tuple(self._view(a) if isinstance(a, Slot) else a for a in kernel.args)
        return Kernel(kernel.function, args, kernel.checked)

    def _allocate(self) -> None:
        s = self._sizes
        self.stacked["G"] = np.zeros((s.get("G", 0), self.n))
        self.stacked["h"] = np.full(s.get("h", 0), np.inf)
        self.stacked["A"] = np.zeros((s.get("A", 0), self.n))
        self.stacked["b"] = np.zeros(s.get("b", 0))
        self.stacked["values"] = np.zeros(s.get("values", 0))
        safe = [v.safe for v in self.verifications]
        tol = [np.full(v.slot.stop - v.slot.start, v.tolerance) for v in self.verifications]
        self.stacked["safe"] = np.concatenate(safe) if safe else np.zeros(0)
        self.stacked["tolerance"] = np.concatenate(tol) if tol else np.zeros(0)

    def _view(self, slot: Slot) -> Array:
        return self.stacked[slot.array][slot.start : slot.stop]
