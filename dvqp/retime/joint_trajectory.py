"""A retimed motion in the field layout of ROS's ``trajectory_msgs/JointTrajectory`` (ROS 2).

``{"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": [...],
"points": [{"positions": [...], "velocities": [...], "accelerations": [...], "effort": [],
"time_from_start": {"sec": s, "nanosec": ns}}, ...]}``: a zero stamp means "start on
receipt"; ``time_from_start`` is whole seconds and nanoseconds, rounded to the nanosecond.
Written as JSON (a YAML reader reads it too); no ROS installation is needed.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def joint_trajectory(
    names: Sequence[str], t: Array, q: Array, qdot: Array, qddot: Array
) -> dict[str, Any]:
    """The message of samples at times ``t`` (M,), s, of joints ``names`` (n): positions
    ``q``, velocities ``qdot`` and accelerations ``qddot`` (M, n), rad, rad/s, rad/s²."""
    nanoseconds = np.rint(np.asarray(t) * 1e9).astype(np.int64)
    points = [
        {
            "positions": q[j].tolist(),
            "velocities": qdot[j].tolist(),
            "accelerations": qddot[j].tolist(),
            "effort": [],
            "time_from_start": {"sec": int(ns // 10**9), "nanosec": int(ns % 10**9)},
        }
        for j, ns in enumerate(nanoseconds)
    ]
    return {
        "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""},
        "joint_names": list(names),
        "points": points,
    }
