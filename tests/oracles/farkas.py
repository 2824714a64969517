"""NumPy oracle of ``solvers.farkas.refuted``: multipliers that prove a QP's constraints admit
no ``x`` within a tolerance, written out from its inequality ``L > U``."""

from __future__ import annotations

from typing import Any

import numpy as np


def proves(problem: Any, y: np.ndarray | None, z: np.ndarray | None, tolerance: float) -> bool:
    """Whether :func:`gap` is above ``1e-12``."""
    return gap(problem, y, z, tolerance) > 1e-12


def gap(problem: Any, y: np.ndarray | None, z: np.ndarray | None, tolerance: float) -> float:
    """``(L − U) / scale``: how far, relative to the magnitude of their terms, the proof's
    two sides stand apart; positive where ``y`` (any sign, the rows of ``A``) and ``z`` (the
    rows of ``G``; a negative one, or one of a row with ``h = +inf``, taken as 0) prove that
    no ``x`` meets
    ``|A x − b| ≤ τ``, ``G x ≤ h + τ``, ``lb − τ ≤ x ≤ ub + τ``: ``min vᵀx`` over the box
    exceeds ``yᵀb + zᵀh + τ(‖y‖₁ + ‖z‖₁)``, ``v = Aᵀy + Gᵀz``, by ``1e-12`` of the terms (NaN
    where a weighed variable is unbounded)."""
    n = problem.lb.shape[0]
    v, size, top, scale = np.zeros(n), np.zeros(n), 0.0, 0.0
    rows = []
    if problem.A is not None and y is not None:
        rows.append((problem.A, problem.b, np.asarray(y, float)))
    if problem.G is not None and z is not None:
        h = np.asarray(problem.h, float)
        w = np.where((np.asarray(z) > 0) & np.isfinite(h), z, 0.0)
        rows.append((problem.G, np.where(np.isfinite(h), h, 0.0), w))
    for M, bound, weight in rows:
        v += M.T @ weight
        size += np.abs(M.T) @ np.abs(weight)
        top += float(weight @ bound) + tolerance * np.abs(weight).sum()
        scale += float(np.abs(weight) @ np.abs(bound)) + tolerance * np.abs(weight).sum()
    lo, hi = problem.lb - tolerance, problem.ub + tolerance
    used = size > 0
    least = np.where(v > 0, v * lo, np.where(v < 0, v * hi, 0.0))[used].sum()
    scale += float((size * np.maximum(np.abs(lo), np.abs(hi)))[used].sum())
    if not np.isfinite(least) or not np.isfinite(scale):
        return float("nan")
    return float((least - top) / scale) if scale > 0 else float("nan")
