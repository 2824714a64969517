"""What a limit gives the QP: inequalities ``Constraint(G, h)`` or a ``Bounds`` box.

dvqp's own limits are compiled (each module holds its kernels). A limit of your own derives
from :class:`Limit` and implements :meth:`Limit.compute` in NumPy (pink's shape), or brings a
compiled kernel (:meth:`Limit.kernel`); a distance kept above a safe value derives from
:class:`~dvqp.limits.VelocityDamper` instead. A run calls a limit of your own after the compiled
parts, on the same state, and writes its rows into the same QP.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from dvqp.kinematics.state import KinematicState
from dvqp.workspace import Kernel, StepPlan
from dvqp.workspace.wiring import StepWiring, overrides


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


SHARED_KEYS = "damper_"
"""The prefix of the ``[constraints]`` keys that several limits share (``damper_gain``)."""


@dataclass(frozen=True)
class SceneLimits:
    """What a scene file gives its limits (:meth:`Limit.from_scene`).

    Attributes
    ----------
    robot : Robot
        The arm.
    obstacles : ObstacleSet
        The scene's obstacles.
    constraints : dict of str to float
        The numbers of its ``[constraints]`` table (validated as numbers).
    qdd_max : ndarray, shape (n,)
        ``[robot] qdd_max``, rad/s².
    """

    robot: Any
    obstacles: Any
    constraints: dict[str, float]
    qdd_max: NDArray[np.float64]


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
    SCENE_KEYS: ClassVar[dict[str, str]] = {}
    """Keys of the scene file's ``[constraints]`` table -> the arguments they give."""
    IN_EVERY_SCENE: ClassVar[bool] = False
    """Whether every scene makes it (with its defaults), not only one giving its keys."""

    @classmethod
    def from_scene(cls, scene: SceneLimits) -> Limit | None:
        """The limit a scene file makes (see :mod:`dvqp.limits.registry`): by default, the
        class called with the ``SCENE_KEYS`` the scene gives; None if it gives none of them
        (unless :attr:`IN_EVERY_SCENE`; the keys every damper shares, ``damper_*``, alone do
        not ask for it)."""
        own = (key for key in cls.SCENE_KEYS if not key.startswith(SHARED_KEYS))
        asked = cls.IN_EVERY_SCENE or any(key in scene.constraints for key in own)
        return cls(**cls.scene_arguments(scene)) if asked else None

    @classmethod
    def scene_arguments(cls, scene: SceneLimits) -> dict[str, float]:
        """The arguments the scene's ``[constraints]`` keys give (see :attr:`SCENE_KEYS`)."""
        values = scene.constraints
        return {param: values[key] for key, param in cls.SCENE_KEYS.items() if key in values}

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

    @property
    def measured(self) -> Sequence[Any]:
        """The obstacles whose distances the step must measure for this limit (none)."""
        return ()

    def join(self, step: StepWiring) -> None:
        """Join the run's step: a limit of your own hands itself to the run's hooks (its
        :meth:`kernel`, else :meth:`compute`, called between the compiled stages); dvqp's own
        limits write their rows into the compiled step's tables instead."""
        step.hooks.limit(self)

    def observe(self, qdot: NDArray[np.float64], dt: float) -> None:
        """The joint velocity (rad/s) applied over the step just taken (a limit that remembers
        motion keeps it; the default forgets it)."""

    @property
    def observes(self) -> bool:
        """Whether the limit keeps the velocity it is shown: its class has an :meth:`observe`
        of its own (the run then shows it every step's)."""
        return overrides(self, Limit, "observe")

    def observed_into(self) -> NDArray[np.float64] | None:
        """Where a run's compiled loop may write the joint velocity (rad/s, (n,)) applied
        over a step instead of calling :meth:`observe` (an array the limit reads), or None:
        its steps call :meth:`observe` from Python. The default, which forgets what it is
        shown, needs neither."""
        return None

    def reset(self) -> None:
        """A run starts (at rest): forget what was observed."""
