"""The fastest motion along a planned joint path, by toppra, sampled at a controller's rate.

The path is the planned samples ``q_k`` with their planned times ``t_k`` as the path parameter
``s`` (samples repeating the one before, where the arm stood still, left out), interpolated by
toppra's ``SplineInterpolator`` (a not-a-knot cubic spline through every kept sample). TOPP-RA
(toppra) finds the fastest ``ṡ(s)`` with ``|q'(s) ṡ| ≤ q̇_max`` and
``|q'(s) s̈ + q''(s) ṡ²| ≤ q̈_max`` per joint at its grid points (every knot and midway between
knots), from rest to rest (``ṡ = 0`` at both ends); its ``ParametrizeConstAccel`` holds ``s̈``
constant between grid points, so the motion stays on the spline. Between grid points the
limits can be exceeded a little (up to some per cent): the motion is then slowed down
uniformly, ``t → k t`` (velocities ``/ k``, accelerations ``/ k²``), with the smallest ``k``
that brings every controller sample within both limits, and the duration rounded up to whole
controller periods so that the last sample is the path's end, at rest.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp import _validate
from dvqp.errors import ParameterError, RetimingError, ShapeError

Array = NDArray[np.float64]

MAX_SAMPLES = 10_000_000
"""The most controller samples a retimed motion may have."""
MAX_STRETCHES = 20
"""How many times the motion is slowed down before the limits are declared unreachable."""


class Samples(NamedTuple):
    """A motion sampled at a controller's rate: ``t`` (M,), s, and per sample ``q``,
    ``qdot``, ``qddot`` (M, n), rad, rad/s, rad/s²."""

    t: Array
    q: Array
    qdot: Array
    qddot: Array


def toppra() -> Any:
    """The toppra package (imported on first use: an optional dependency, ``dvqp[retime]``).

    Raises
    ------
    RetimingError
        toppra is not installed.
    """
    try:
        import toppra
        import toppra.algorithm
        import toppra.constraint
    except ImportError as exc:
        raise RetimingError(f"retiming needs toppra ({exc}): pip install 'dvqp[retime]'") from exc
    return toppra


def parameterise(q: Array, t: Array, qd_max: Array, qdd_max: Array, rate: float) -> Samples:
    """The fastest motion along the path of the samples ``q`` (N+1, n) planned at times ``t``
    (N+1,), s, within ``qd_max`` and ``qdd_max`` (n,), rad/s and rad/s², from rest to rest,
    sampled every ``1 / rate`` s (``rate`` in Hz).

    Raises
    ------
    ParameterError
        ``rate`` is not a number > 0, or gives more than :data:`MAX_SAMPLES` samples.
    RetimingError
        The path does not move, no motion along it keeps the limits, or toppra is missing.
    """
    rate = _validate.positive("rate", rate)
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    if q.ndim != 2 or t.ndim != 1 or q.shape != (t.size, np.size(qd_max)):
        raise ShapeError("q", (t.size, np.size(qd_max)), q.shape)
    if not (np.all(np.isfinite(q)) and np.all(np.diff(t) > 0.0)):
        raise ParameterError("q, t", "must be finite, t increasing")
    moved = np.flatnonzero(np.any(np.diff(q, axis=0) != 0.0, axis=1)) + 1
    kept = np.concatenate([[0], moved])
    if kept.shape[0] < 2:
        raise RetimingError("the planned path does not move: there is nothing to retime")
    ta = toppra()
    s = t[kept]
    path = ta.SplineInterpolator(s, q[kept])
    grid = np.union1d(s, 0.5 * (s[1:] + s[:-1]))
    limits = [
        ta.constraint.JointVelocityConstraint(np.column_stack([-qd_max, qd_max])),
        ta.constraint.JointAccelerationConstraint(np.column_stack([-qdd_max, qdd_max])),
    ]
    algorithm = ta.algorithm.TOPPRA(
        limits, path, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    )
    found = algorithm.compute_trajectory(0.0, 0.0)
    if found is None or not math.isfinite(found.duration) or found.duration <= 0.0:
        raise RetimingError(
            "no motion along the planned path keeps the joint velocity and acceleration limits "
            "(toppra found none)"
        )
    return sampled(found, np.asarray(qd_max), np.asarray(qdd_max), rate)


def sampled(motion: Any, qd_max: Array, qdd_max: Array, rate: float) -> Samples:
    """``motion`` (toppra's, ``motion(τ, order)`` for τ in ``[0, motion.duration]``) slowed
    down uniformly by the least factor that keeps every sample every ``1 / rate`` s within
    ``qd_max`` and ``qdd_max``, the duration a whole number of periods."""
    duration = float(motion.duration)
    scale = 1.0
    for _ in range(MAX_STRETCHES):
        periods = max(math.ceil(duration * scale * rate - 1e-9), 1)
        if periods + 1 > MAX_SAMPLES:
            raise ParameterError(
                "rate", f"{rate:g} Hz gives {periods + 1:.3g} samples, more than {MAX_SAMPLES:.0e}"
            )
        scale = periods / (rate * duration)
        t = np.arange(periods + 1) / rate
        tau = np.minimum(t / scale, duration)
        qdot, qddot = motion(tau, 1) / scale, motion(tau, 2) / scale**2
        qdot[[0, -1]] = 0.0  # ṡ = 0 there: what is left is round-off
        use = max(
            float(np.max(np.abs(qdot) / qd_max)), math.sqrt(float(np.max(np.abs(qddot) / qdd_max)))
        )
        q = motion(tau)
        if not (math.isfinite(use) and np.all(np.isfinite(q))):
            break
        if use <= 1.0:
            return Samples(t, q, qdot, qddot)
        scale *= use
    raise RetimingError(
        "the retimed motion could not be brought within the joint velocity "
        "and acceleration limits at the controller's samples"
    )
