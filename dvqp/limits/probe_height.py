"""The probe may touch the pipe surface but never go below it."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from dvqp.errors import ParameterError
from dvqp.limits.damper import DEFAULT_DECELERATION, VelocityDamper


class ProbeHeight(VelocityDamper):
    """``h_tool ≥ floor`` for the probe (the tool point), one damper row ``"probe/height"``
    (compiled: :func:`~dvqp.limits.surface_height.height_distances` of the last guarded point).

    The body points keep ``min_height`` (:class:`~dvqp.limits.SurfaceHeight`); the probe, which
    inspects the surface, only has to stay out of the pipe wall.

    Parameters
    ----------
    floor
        Lowest probe height, m (default 0: touching the surface is allowed).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
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

    @property
    def safe(self) -> float:
        """``floor``, m."""
        return self.floor

    def labels(self, k: int) -> tuple[str, ...]:
        """``("probe/height",)``."""
        return ("probe/height",)
