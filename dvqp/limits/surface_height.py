"""The body points stay above a minimum height over the pipe surface."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from dvqp.compiled.plan import Kernel, StepPlan
from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper
from dvqp.limits.damper_kernels import height_rows, height_values


class SurfaceHeight(VelocityDamper):
    """``h_i ≥ h_min`` for every body point, as a damper row each (labels ``"point3/height"``).

    Parameters
    ----------
    min_height
        ``h_min``, m (finite).
    gain
        ``γ`` in (0, 1].
    """

    name = "height"
    quantity = "height"
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "min_height": "min_height",
        "damper_gain": "gain",
    }
    """Keys of the scene file's ``[constraints]`` table -> constructor arguments."""

    def __init__(
        self, min_height: float = 0.0, gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:  # fmt: skip
        super().__init__(gain, deceleration)
        if not np.isfinite(min_height):
            raise ParameterError("min_height", "must be finite")
        self.min_height = float(min_height)

    def distances(self, state: KinematicState) -> Distances:
        """The body points' heights h (m) and ``∂h/∂Q``, safe value ``h_min``."""
        k = state.points.shape[0]
        return Distances(
            state.points[:, 2],
            state.point_jacobians[:, 2, :],
            self.min_height,
            lambda: tuple(f"point{i + 1}/height" for i in range(k)),
        )

    def kernel(self, plan: StepPlan) -> Kernel:
        """k rows, one per body point (all always apply), from ``plan.state``."""
        G, h = plan.constraint_rows(plan.k)
        s = plan.state
        params = self.params(self.min_height)
        return Kernel(height_rows, (s.guarded, s.guarded_jacobians, 0, params, plan.dt, G, h))

    def verifier(self, plan: StepPlan) -> Kernel:
        """The k body points' heights, m (safe value ``h_min``)."""
        slot = plan.verified(self, plan.k, self.min_height, self.tolerance)
        return Kernel(height_values, (plan.state.guarded, 0, slot))
