r"""qpbenchmark's accuracy metrics of a solve, and their shifted geometric means.

For a solution ``(x, y, z, z_box)`` of ``min ½xᵀPx + qᵀx  s.t.  Ax = b, Gx ≤ h, lb ≤ x ≤ ub``
(the multiplier signs of :mod:`solvers.residuals`), as qpbenchmark defines them:

.. math::

    r_p &= \max(\|Ax - b\|_\infty, [Gx - h]^+, [lb - x]^+, [x - ub]^+) \\
    r_d &= \|Px + q + A^T y + G^T z + z_{box}\|_\infty \\
    r_g &= |x^T P x + q^T x + b^T y + h^T z + lb^T z_{box}^- + ub^T z_{box}^+|

Rows with an infinite ``h`` or bound are left out of ``r_g`` (their multiplier must be 0; the
complementarity check of :func:`solvers.residuals.failed_checks` refuses one that is not).
All three are computed from the problem data by the one KKT kernel (:mod:`solvers.kkt`) with
the answer's check (:attr:`Solution.residuals <solvers.Solution.residuals>`), never taken from
the solver.

A run's figure is the shifted geometric mean ``exp(mean(log(v + s))) − s`` with qpbenchmark's
shift ``s = 10``; a solve without an accepted answer counts as the tolerance of its check
(qpbenchmark counts an unsolved problem at its tier's tolerance). :class:`AccuracyTally` keeps
the sums, so tallies of many runs merge exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba.extending import register_jitable

from .residuals import Residuals
from .solution import Solution

#: qpbenchmark's shift of the shifted geometric mean.
SHIFT = 10.0

#: The metrics, in order: primal residual, dual residual, duality gap.
METRICS = ("primal_residual", "dual_residual", "duality_gap")


def metrics(solution: Solution) -> tuple[float, float, float] | None:
    """``(r_p, r_d, r_g)`` of an accepted answer; None if it was not accepted or lacks a
    multiplier (it then counts at its tolerance, see :meth:`AccuracyTally.add`)."""
    return metrics_of(solution.residuals) if solution.found else None


def metrics_of(res: Residuals | None) -> tuple[float, float, float] | None:
    """``(r_p, r_d, r_g)`` of an accepted answer's residuals; None without a multiplier."""
    if res is None or res.stationarity is None or res.duality_gap is None:
        return None
    return _metrics(res.equality, res.inequality, res.bounds, res.stationarity, res.duality_gap)


@register_jitable
def kernel_metrics(values: tuple[float, ...]) -> tuple[float, float, float]:
    """``(r_p, r_d, r_g)`` of the kernel ``values`` of an answer that passed the check
    (:func:`solvers.residuals.accepts`: it has every multiplier)."""
    _, equality, inequality, bounds, stationarity, _, _, gap = values
    return _metrics(equality, inequality, bounds, stationarity, gap)


@register_jitable
def _metrics(
    equality: float, inequality: float, bounds: float, stationarity: float, gap: float
) -> tuple[float, float, float]:
    """qpbenchmark's primal residual, dual residual and duality gap."""
    return max(equality, inequality, bounds), stationarity, gap


@register_jitable
def log_term(value: float) -> float:
    """A metric's term in its running sum (:attr:`AccuracyTally.log_sums`):
    ``log1p(value / SHIFT)``."""
    return math.log1p(value / SHIFT)


@register_jitable
def add_kernel_metrics(log_sums: np.ndarray, values: tuple[float, ...]) -> None:
    """:meth:`AccuracyTally.add_metrics` of an accepted answer's kernel ``values``
    (:func:`kernel_metrics`) made in compiled code: its terms added to ``log_sums`` (3,), the
    tally's sums, in place (the caller counts the solve)."""
    metrics = kernel_metrics(values)
    for i in range(3):
        log_sums[i] += log_term(metrics[i])


def shifted_geometric_mean(values: np.ndarray | list[float], shift: float = SHIFT) -> float:
    """``exp(mean(log(v + shift))) − shift``, computed as ``shift·expm1(mean(log1p(v/shift)))``
    so that residuals far below ``shift`` keep their digits.

    Raises
    ------
    ValueError
        No value, a negative or non-finite one, or ``shift < 1`` (qpbenchmark's condition).
    """
    array = np.asarray(values, dtype=np.float64)
    if array.size == 0 or not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ValueError("shifted geometric mean: needs finite values >= 0")
    if shift < 1.0:
        raise ValueError(f"shifted geometric mean: shift {shift} < 1")
    return float(shift * math.expm1(float(np.mean(np.log1p(array / shift)))))


@dataclass
class AccuracyTally:
    """Running shifted geometric means of the metrics over solves (and over runs, merged).

    Attributes
    ----------
    solves : int
        Backend calls counted.
    unanswered : int
        Of those, the calls counted at their tolerance (no accepted answer with multipliers).
    log_sums : list of float
        ``Σ log1p(v / SHIFT)`` per metric, in :data:`METRICS` order.
    """

    solves: int = 0
    unanswered: int = 0
    log_sums: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def add(self, solution: Solution) -> None:
        """Count one backend call: its metrics, or its check's tolerance if unanswered."""
        self.add_metrics(metrics(solution), solution.tolerance)

    def add_metrics(self, values: tuple[float, float, float] | None, tolerance: float) -> None:
        """Count one backend call by its :func:`metrics` (None: unanswered, counted at its
        check's ``tolerance``)."""
        if values is None:
            self.unanswered += 1
            values = (tolerance,) * 3
        self.solves += 1
        for i, value in enumerate(values):
            self.log_sums[i] += log_term(value)

    def merge(self, other: AccuracyTally) -> None:
        """Add another tally's solves (e.g. another run's)."""
        self.solves += other.solves
        self.unanswered += other.unanswered
        self.log_sums = [a + b for a, b in zip(self.log_sums, other.log_sums, strict=True)]

    def means(self) -> dict[str, float] | None:
        """Shifted geometric mean of each metric (None: no solve counted)."""
        if not self.solves:
            return None
        return {
            name: SHIFT * math.expm1(total / self.solves)
            for name, total in zip(METRICS, self.log_sums, strict=True)
        }

    def to_dict(self) -> dict[str, float | int]:
        """JSON-ready: ``solves``, ``unanswered`` and the three means (none if no solve)."""
        return {"solves": self.solves, "unanswered": self.unanswered, **(self.means() or {})}

    @classmethod
    def from_dict(cls, data: dict[str, float | int]) -> AccuracyTally:
        """The tally :meth:`to_dict` wrote (its means turned back into sums)."""
        solves = int(data.get("solves", 0))
        tally = cls(solves, int(data.get("unanswered", 0)))
        if solves:
            tally.log_sums = [solves * math.log1p(float(data[name]) / SHIFT) for name in METRICS]
        return tally
