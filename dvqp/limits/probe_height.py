"""The probe may touch the pipe surface but never go below it."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.damper_kernels import height_rows, height_values


class ProbeHeight(VelocityDamper):
    """``h_tool ≥ floor`` for the probe (the tool point), one damper row ``"probe/height"``.

    The body points keep ``min_height`` (:class:`~dvqp.limits.SurfaceHeight`); the probe, which
    inspects the surface, only has to stay out of the pipe wall.

    Parameters
    ----------
    floor
        Lowest probe height, m (default 0: touching the surface is allowed).
    gain
        ``γ`` in (0, 1].
    """

    name = "probe_height"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, floor: float = 0.0, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        if not np.isfinite(floor):
            raise ParameterError("floor", "must be finite")
        self.floor = float(floor)

    def distances(self, state: KinematicState) -> Distances:
        """The tool's height h (m) and ``∂h/∂Q``, the third row of the DV task Jacobian."""
        return Distances(
            state.guarded[-1:, 2], state.guarded_jacobians[-1:, 2, :], self.floor,
            lambda: ("probe/height",),
        )  # fmt: skip

    def kernel(self, plan: StepPlan) -> Kernel:
        """The probe's row (guarded point k), from ``plan.state``."""
        G, h = plan.constraint_rows(1)
        s, params = plan.state, self.params(self.floor)
        return Kernel(height_rows, (s.guarded, s.guarded_jacobians, plan.k, params, plan.dt, G, h))

    def verifier(self, plan: StepPlan) -> Kernel:
        """The probe's height, m (safe value ``floor``)."""
        slot = plan.verified(self, 1, self.floor, self.tolerance)
        return Kernel(height_values, (plan.state.guarded, plan.k, slot))
