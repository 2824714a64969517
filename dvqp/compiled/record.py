"""A compiled sample of the trajectory: the loaded state written into the recorder's arrays."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numba import njit
from numpy.typing import NDArray

from dvqp.compiled.buffers import Kernel, StateBuffers

Array = NDArray[np.float64]

SAMPLED = ("q", "tool", "points", "w", "limit_excess", "limits_kept", "tilt", "self_distance",
           "min_clearance", "probe_clearance")  # fmt: skip
"""The recorder's per-sample arrays this kernel writes (see
:class:`~dvqp.motion.recorder.TrajectoryRecorder`)."""


@njit(cache=True)
def record_sample(  # type: ignore[no-untyped-def]
    index, q, tool, points, w, limit_excess, limits_kept, tilt, self_distance, min_clearance,
    probe_clearance, state_q, state_tool, guarded, value, excess, diagnostics,
) -> None:  # fmt: skip
    """Row ``index[0]`` of the sample arrays from the state buffers, the objective value, the
    worst excess ``[value, ratio]`` and the diagnostics ``[tilt, self distance, min clearance,
    probe clearance]`` (as :meth:`~dvqp.motion.recorder.TrajectoryRecorder.sample_values`)."""
    k = index[0]
    q[k] = state_q
    tool[k] = state_tool
    points[k] = guarded[: points.shape[1]]
    w[k] = value[0]
    limit_excess[k] = max(excess[0], 0.0)
    limits_kept[k] = excess[1] <= 1.0
    tilt[k], self_distance[k] = diagnostics[0], diagnostics[1]
    min_clearance[k], probe_clearance[k] = diagnostics[2], diagnostics[3]


def sample_kernel(
    index: NDArray[np.int64], samples: Mapping[str, np.ndarray], state: StateBuffers,
    value: Array, excess: Array, diagnostics: Array,
) -> Kernel:  # fmt: skip
    """The kernel writing the loaded state into row ``index[0]`` of ``samples``."""
    arrays = tuple(samples[name] for name in SAMPLED)
    return Kernel(record_sample, (index, *arrays, state.q, state.tool, state.guarded, value,
                                  excess, diagnostics))  # fmt: skip
