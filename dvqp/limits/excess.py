"""Exact verification of a step: how far the integrated motion went past each limit.

The QP holds the limits linearised one step ahead; the motion that is integrated may still
go past them (second-order terms, large steps). After each step every verified limit's exact
quantities (clearances, heights, tilt, joint room, ...) are evaluated at the configuration
reached, without linearisation, and the worst :class:`Excess` is kept.

A quantity is kept while at or above ``min(safe, value at the run's start)``: a part that
starts inside its margin may stay there but not get worse, and excesses cannot add up. Such a
start is not hidden: the values it broke are reported (:class:`StartBroken`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from dvqp.workspace.buffers import Array
from solvers.jit import njit


@dataclass(frozen=True)
class Excess:
    """How far a motion went past one limit, in the limit's unit.

    Attributes
    ----------
    value : float
        Amount past the bound (> 0 broken, <= 0 kept with that much room), m or rad.
    tolerance : float
        The limit's verification tolerance, same unit: the step is accepted up to it.
    label : str
        What broke it, e.g. ``"probe/obstacles[2]"``, ``"point2/height"``, ``"joint4"``.
    quantity : str
        ``"clearance"``, ``"height"``, ``"tilt"``, ``"joint position"``, ...
    unit : str
        ``"m"`` or ``"rad"``.
    actual, bound : float
        The value reached and the bound it had to keep.
    """

    value: float
    tolerance: float
    label: str = ""
    quantity: str = ""
    unit: str = ""
    actual: float = 0.0
    bound: float = 0.0

    @property
    def broken(self) -> bool:
        """Past the bound by more than the tolerance (a NaN value counts as past it)."""
        return not self.value <= self.tolerance

    @property
    def ratio(self) -> float:
        """``value / tolerance``: how the worst of several limits is chosen."""
        return self.value / self.tolerance

    def describe(self) -> str:
        """One line, e.g. ``"probe/obstacles[2] clearance 0.0061 m < 0.0099 m (by 3.8 mm)"``."""
        if math.isinf(self.value):
            return f"{self.label} ({self.quantity})"
        by = amount(self.value, self.unit)
        below = "<" if self.quantity not in ("joint position", "joint velocity") else "past"
        return (
            f"{self.label} {self.quantity} {self.actual:.4g} {self.unit} {below} "
            f"{self.bound:.4g} {self.unit} (by {by})"
        )


NO_EXCESS = Excess(value=-math.inf, tolerance=1.0)
"""What a step with nothing to check reports."""


def amount(value: float, unit: str) -> str:
    """``"3.8 mm"`` for metres, else ``"0.159 rad"``."""
    return f"{value * 1e3:.3g} mm" if unit == "m" else f"{value:.3g} {unit}"


@dataclass(frozen=True)
class StartBroken:
    """A verified value that the run's start put past its bound and that a saved sample has
    past it by more than its tolerance: the run was held only to keep it no worse.

    Attributes
    ----------
    limit : str
        What sets the bound: the scene key (``"min_height"``, ``"margin"``), else the
        limit's name.
    label, quantity, unit : str
        As in :class:`Excess` (``"point2/height"``, ``"height"``, ``"m"``).
    bound, start, lowest : float
        The bound (the limit's safe value), the value at the start and the smallest at any
        saved sample, in ``unit``.
    tolerance : float
        The limit's verification tolerance, same unit.
    """

    limit: str
    label: str
    quantity: str
    unit: str
    bound: float
    start: float
    lowest: float
    tolerance: float

    @property
    def excess(self) -> Excess:
        """How far past the bound at worst over the run (the true figure, not the start's)."""
        return Excess(
            self.bound - self.lowest,
            self.tolerance,
            self.label,
            self.quantity,
            self.unit,
            self.lowest,
            self.bound,
        )

    @property
    def worse(self) -> float:
        """How much further past it than at the start a sample went (<= tolerance: never
        worse)."""
        return self.start - self.lowest


def start_broken_lines(found: Sequence[StartBroken]) -> list[str]:
    """One line per limit (in order of first appearance): its worst value, e.g.
    ``"min_height: broken from the start by 21.3 mm (point2/height and 4 more), never worse"``;
    a limit that got worse says by how much (``"…, 5.1 mm worse than at the start"``)."""
    lines = []
    for limit in dict.fromkeys(b.limit for b in found):
        group = [b for b in found if b.limit == limit]
        top = max(group, key=lambda b: b.excess.ratio)
        more = f" and {len(group) - 1} more" if len(group) > 1 else ""
        worst = max(group, key=lambda b: b.worse / b.tolerance)
        then = (
            "never worse"
            if worst.worse <= worst.tolerance
            else f"{amount(worst.worse, worst.unit)} worse than at the start"
        )
        lines.append(
            f"{limit}: broken from the start by {amount(top.excess.value, top.unit)} "
            f"({top.label}{more}), {then}"
        )
    return lines


@njit(separate=True)
def worst_excess(values: Array, floor: Array, tolerance: Array, out: Array) -> int:
    """``out = [floor − value, (floor − value)/tolerance]`` of the value of largest ratio
    (``[−inf, −inf]`` if none); returns its index, or −1. A NaN is the worst (never kept)."""
    best, best_v, best_r = -1, -math.inf, -math.inf
    for i in range(values.shape[0]):
        over = floor[i] - values[i]
        ratio = over / tolerance[i]
        if ratio > best_r or ratio != ratio:
            best, best_v, best_r = i, over, ratio
            if ratio != ratio:
                break
    out[0], out[1] = best_v, best_r
    return best
