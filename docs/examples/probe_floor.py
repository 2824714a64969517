"""A user-written limit: the probe (the tool point) stays above a floor over the pipe surface.

It derives from :class:`dvqp.VelocityDamper`, which owns the damper's rows
``−∇d·Q̇ ≤ rhs(d − d_safe)`` and their exact verification: the subclass only says which distance
it keeps — the tool's height h, whose gradient is the third row of the DV task Jacobian — and
its safe value. :class:`ProbeFloor` does it in NumPy; :class:`CompiledProbeFloor` brings the
same distance as a numba kernel, which a run calls without leaving compiled code's arrays.
"""

from __future__ import annotations

from numba import njit

from dvqp import Distances, Kernel, KinematicState, PartNames, StepPlan, VelocityDamper


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


@njit(cache=True)
def probe_height(tool, tool_jacobian, distance, gradient, usable):  # type: ignore[no-untyped-def]
    """The tool's height (m) and ``∂h/∂Q`` into the damper's one row."""
    distance[0], usable[0] = tool[2], True
    for c in range(gradient.shape[1]):
        gradient[0, c] = tool_jacobian[2, c]


class CompiledProbeFloor(ProbeFloor):
    """:class:`ProbeFloor` with its distance as a compiled kernel."""

    @property
    def safe(self) -> float:
        """``floor``, m."""
        return self.floor

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``("probe/floor",)``: the probe's name (``names``: the arm's guarded parts)."""
        return (f"{names.probe}/floor",)

    def kernel(self, plan: StepPlan) -> Kernel:
        """One damper row, written from the tool's DV coordinates at every state."""
        distance, gradient, usable = plan.damper_rows(1)
        s = plan.state
        return Kernel(probe_height, (s.tool, s.tool_jacobian, distance, gradient, usable))


__all__ = ["CompiledProbeFloor", "ProbeFloor"]
