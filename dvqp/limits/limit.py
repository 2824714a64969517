"""What a limit gives the QP: inequalities ``Constraint(G, h)`` or a ``Bounds`` box.

dvqp's own limits are compiled (each module holds its kernels). A limit of your own derives
from :class:`Limit` and implements :meth:`Limit.compute` in NumPy (pink's shape), or brings a
compiled kernel (:meth:`Limit.kernel`); a distance kept above a safe value derives from
:class:`~dvqp.limits.VelocityDamper` instead. A run calls a limit of your own after the compiled
parts, on the same state, and writes its rows into the same QP.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.workspace import Kernel, StepPlan


@dataclass(frozen=True)
class Constraint:
    """Linear inequalities ``G Q̇ ≤ h`` on the joint velocities, with a label per row.

    Attributes
    ----------
    G : ndarray, shape (p, n)
    h : ndarray, shape (p,)
        Usually m/s (a damper) or rad/s; ``+inf`` for a row that does not apply.
    describe : callable, optional
        Returns what each row holds, e.g. ``"point3/obstacles[0]"``; called only when
        :attr:`labels` is read.
    """

    G: NDArray[np.float64]
    h: NDArray[np.float64]
    describe: Callable[[], tuple[str, ...]] | None = field(default=None, repr=False)

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per row (``"row{i}"`` where none was given)."""
        if self.describe is None:
            return tuple(f"row{i}" for i in range(self.rows))
        return self.describe()

    @property
    def rows(self) -> int:
        """Number of rows p."""
        return int(self.h.shape[0])


@dataclass(frozen=True)
class Bounds:
    """Box ``lb ≤ Q̇ ≤ ub`` on the joint velocities, rad/s, each shape (n,)."""

    lb: NDArray[np.float64]
    ub: NDArray[np.float64]


class Limit:
    """A hard limit of the QP step, linear in ``Q̇`` at the current state.

    Pass it in ``StepSpec.limits`` (or ``dvqp.plan(..., limits=[...])``); the pseudoinverse
    baseline ignores limits.

    Attributes
    ----------
    name : str
        A label for reports.
    """

    name: str = "limit"

    def compute(self, state: KinematicState, dt: float) -> Constraint | Bounds:
        """The limit's rows at ``state`` for a step of ``dt`` seconds (a limit of your own).

        A :class:`Constraint` must have the same number of rows at every state of a run
        (``h = +inf`` for a row that does not apply).
        """
        raise NotImplementedError(f"{type(self).__name__} has no compute(state, dt)")

    def kernel(self, plan: StepPlan) -> Kernel | None:
        """Optionally, the limit's rows as a compiled kernel: ask ``plan`` for rows once
        (``G, h = plan.constraint_rows(p)``) and return a :class:`~dvqp.workspace.Kernel`
        writing them from ``plan.state`` and ``plan.dt`` at every step (or intersecting its
        box into ``plan.lb``, ``plan.ub``). None (the default): :meth:`compute` is used."""
        return None

    def observe(self, qdot: NDArray[np.float64], dt: float) -> None:
        """The joint velocity (rad/s) applied over the step just taken (a limit that remembers
        motion keeps it; the default forgets it)."""

    def reset(self) -> None:
        """A run starts (at rest): forget what was observed."""
