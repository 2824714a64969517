"""Small input checks shared by the constructors (private)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from dvqp.errors import ParameterError, ShapeError


def vector(name: str, value: ArrayLike, n: int | None = None) -> NDArray[np.float64]:
    """Return ``value`` as a finite float64 vector of length ``n`` (any length if None), a copy
    (so that marking it read-only never freezes the caller's array)."""
    arr = np.array(value, dtype=np.float64)
    if arr.ndim != 1 or (n is not None and arr.shape[0] != n):
        raise ShapeError(name, (-1 if n is None else n,), arr.shape)
    if not np.isfinite(arr).all():
        raise ParameterError(name, "must be finite (no NaN or inf)")
    return arr


def broadcast(name: str, value: ArrayLike, n: int) -> NDArray[np.float64]:
    """Return a scalar or a length-``n`` sequence as a finite float64 vector of length ``n``."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    return vector(name, arr, n)


def limit(name: str, value: ArrayLike, n: int) -> NDArray[np.float64]:
    """Return a scalar or length-``n`` limit as a float64 vector of length ``n``; ±inf allowed
    (no limit), NaN not."""
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ShapeError(name, (n,), arr.shape)
    if np.any(np.isnan(arr)):
        raise ParameterError(name, "must not be NaN")
    return arr.copy()


def positive(name: str, value: float, *, strict: bool = True) -> float:
    """Return ``value`` as a float, checking it is finite and > 0 (>= 0 if not strict)."""
    v = float(value)
    if not np.isfinite(v) or (v <= 0 if strict else v < 0):
        raise ParameterError(name, f"must be {'>' if strict else '>='} 0, got {value!r}")
    return v


def readonly(arr: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mark ``arr`` read-only and return it."""
    arr.flags.writeable = False
    return arr
