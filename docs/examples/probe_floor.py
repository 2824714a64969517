"""A user-written limit: the probe (the tool point) stays above a floor over the pipe surface.

It derives from :class:`dvqp.VelocityDamper`, which owns the damper's right-hand side
``γ/dt · max(d − d_safe, −δ)``: the subclass only says which distance it keeps (the tool's
height h, with gradient the third row of the DV task Jacobian) and its safe value.
"""

from __future__ import annotations

from dvqp import KinematicState, VelocityDamper
from dvqp.limits import Distances


class ProbeFloor(VelocityDamper):
    """``h_tool ≥ floor`` (m), as one damper row labelled ``"probe/floor"``.

    Parameters
    ----------
    floor
        Lowest probe height over the pipe surface, m.
    gain
        γ in (0, 1].
    """

    name = "probe_floor"

    def __init__(self, floor: float = 0.0, gain: float = 0.5) -> None:
        super().__init__(gain)
        self.floor = floor

    def distances(self, state: KinematicState) -> Distances:
        """The tool's height h (m) and ``∂h/∂Q``."""
        return Distances(
            state.tool[2:3], state.tool_jacobian[2:3], self.floor, lambda: ("probe/floor",)
        )
