"""A weld path for the tool: waypoints in the developed view, followed at constant speed."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.kinematics.developed_view import wrap, wrap_angle
from dvqp.motion.jog import MAX_STEPS

HEADING_ARM = 0.1
"""m/rad: a path segment's heading change counts as this much length (at 0.02 m/s along the
path, the probe turns at 0.2 rad/s)."""


@dataclass(frozen=True)
class ToolPath:
    """A DV path for the tool, followed with position feedback.

    Attributes
    ----------
    waypoints : ndarray, shape (m, 4)
        ``[l, z, h, α]`` (m, m, m, rad), l unwrapped (it may run past ``±πR``).
    speed : float
        Speed along the (l, z, h) polyline, m/s.
    gain : float
        Feedback gain ``K``, 1/s.
    tolerance, heading_tolerance : float
        Largest final position error (l, z, h; m) and heading error (rad) counted as reached.
    timing : str
        ``"fixed"``: at ``speed`` throughout, the task relaxed where the limits bind (the
        paper's); ``"scaled"``: a QP slows along the path there instead
        (:mod:`dvqp.motion.schedule`).
    """

    waypoints: NDArray[np.float64]
    speed: float
    gain: float = 5.0
    tolerance: float = 0.005
    heading_tolerance: float = 0.05
    timing: str = "fixed"

    @staticmethod
    def segment_lengths(nodes: NDArray[np.float64]) -> NDArray[np.float64]:
        """Length (m) of each segment between consecutive ``[l, z, h, α]`` nodes, shape (m−1,).

        A segment lasts as long as its (l, z, h) length or its heading change counted at
        :data:`HEADING_ARM` m/rad, whichever is longer, so a turn in place takes time too.
        """
        delta = np.diff(nodes, axis=0)
        return np.maximum(np.linalg.norm(delta[:, :3], axis=1), HEADING_ARM * np.abs(delta[:, 3]))

    def step_count(self, dt: float) -> float:
        """About how many steps of ``dt`` the waypoints take (from the first one)."""
        return float(self.segment_lengths(self.waypoints).sum()) / (self.speed * dt)

    def reference(
        self, start: NDArray[np.float64], dt: float, radius: float
    ) -> NDArray[np.float64]:
        """``x_d(t_k)``, shape (N+1, 4): constant speed along the (l, z, h) polyline from the
        tool's DV position ``start`` (shape (4,)), every ``dt`` s, on a pipe of ``radius`` m.

        The waypoints are shifted by whole turns (2πR in l, 2π in α) so the first lies nearest
        the tool's start; the tool first moves from ``start`` to it, then along the waypoints.
        α is interpolated linearly along the arc length. ``N = ⌈length / (speed·dt)⌉``; the
        last row is the last waypoint.
        """
        wp = np.array(self.waypoints, dtype=float)
        wp[:, 0] += start[0] + wrap(wp[0, 0] - start[0], radius) - wp[0, 0]
        wp[:, 3] += start[3] + wrap_angle(wp[0, 3] - start[3]) - wp[0, 3]
        nodes = np.vstack([start, wp])
        seg = self.segment_lengths(nodes)
        keep = np.concatenate([[True], seg > 0.0])
        nodes, s = nodes[keep], np.concatenate([[0.0], np.cumsum(seg[seg > 0.0])])
        n_steps = max(1, math.ceil(s[-1] / (self.speed * dt) - 1e-9))
        if n_steps > MAX_STEPS:
            raise ParameterError(
                "motion.path", f"{n_steps} steps is too many (at most {MAX_STEPS})"
            )
        arc = np.minimum(self.speed * dt * np.arange(n_steps + 1), s[-1])
        return np.column_stack([np.interp(arc, s, nodes[:, c]) for c in range(4)])
