"""What a run's verified values say: the worst excess of a state, the limits its start broke.

:class:`Verification` is part of :class:`~dvqp.step.engine.Stepper`: it reads the exact values
its compiled conclusion wrote (``arrays.checks``) and names them by the limit and part they
belong to (the layout's blocks, or a user part's own labels).
"""

from __future__ import annotations

import numpy as np

from dvqp.kinematics.robot import Robot
from dvqp.limits.excess import NO_EXCESS, Excess, StartBroken
from dvqp.step.arrays import Pipeline
from dvqp.step.build import Block, Layout
from dvqp.step.hooks import Hooks


class Verification:
    """The naming of a stepper's verified values (see the module docstring)."""

    robot: Robot
    arrays: Pipeline
    layout: Layout
    hooks: Hooks

    def excess(self) -> Excess:
        """The worst excess of the loaded state, named (:data:`~dvqp.limits.NO_EXCESS` with
        nothing to verify)."""
        c = self.arrays.checks
        over = c.floor - c.values
        if over.shape[0] == 0:
            return NO_EXCESS
        ratio = over / c.tolerance
        i = int(np.argmax(np.where(np.isnan(ratio), np.inf, ratio)))
        broken = not over[i] <= 0.0  # past the floor, or NaN
        limit, label = self._named(i) if broken else (self._block(i).limit, "")
        if not self._block(i).damper:  # the joints' room: reported as their positions
            n, at = self.robot.n, i - self._block(i).start
            q = float(self.arrays.state.q[at % n])
            bound = q - over[i] if at < n else q + over[i]
            return Excess(
                float(over[i]),
                float(c.tolerance[i]),
                label,
                "joint position",
                "rad",
                q,
                float(bound),
            )
        return Excess(
            float(over[i]),
            float(c.tolerance[i]),
            label,
            limit.quantity,
            limit.unit,  # type: ignore[attr-defined]
            float(c.values[i]),
            float(c.floor[i]),
        )

    def start_broken(self) -> tuple[StartBroken, ...]:
        """The verified values the run's start put below their safe value that a recorded
        sample (since :meth:`start`) has below it by more than its tolerance."""
        c = self.arrays.checks
        found = np.flatnonzero((c.floor < c.safe) & (c.lowest < c.safe - c.tolerance))
        return tuple(self._start_broken(int(i)) for i in found)

    def _start_broken(self, i: int) -> StartBroken:
        c, (limit, label) = self.arrays.checks, self._named(i)
        keys = [k for k in getattr(limit, "SCENE_KEYS", {}) if not k.startswith("damper_")]
        kind = (limit.quantity, limit.unit)  # type: ignore[attr-defined]
        values = (float(a[i]) for a in (c.safe, c.floor, c.lowest, c.tolerance))
        return StartBroken(keys[0] if keys else limit.name, label, *kind, *values)  # type: ignore[attr-defined]

    def _block(self, i: int) -> Block:
        return next(b for b in self.layout.blocks if b.start <= i < b.stop)

    def _named(self, i: int) -> tuple[object, str]:
        """The limit of verified value ``i`` and the value's label."""
        block = self._block(i)
        describe = self.hooks.describes.get(id(block.limit))
        return block.limit, (describe() if describe else block.labels)[i - block.start]
