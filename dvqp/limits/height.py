"""Heights over the pipe surface: the body above a minimum, the probe out of the wall.

Both are dampers of heights ``h`` (m) over the surface: of guarded points (``∂h/∂Q`` the third
row of their DV Jacobian, compiled: :func:`height_distances`) and of the lowest point of guarded
links (:func:`chord_heights`). A link is a straight 3-D chord between its ends, which dips below
them: with ``P(t) = A + t (B − A)`` its distance from the pipe axis ``ρ(t) = ‖a + t e‖``
(``a``, ``e`` the xy parts of ``A``, ``B − A``) is least at ``t* = clamp(−a·e / e·e, 0, 1)``,
so ``h = ρ(t*) − R`` exactly, and ``∂h/∂Q = (P_xy(t*)/ρ)ᵀ ((1 − t*) J_A + t* J_B)`` (the
envelope theorem: moving ``t*`` does not change ``ρ`` to first order). A chord's row applies
where ``t*`` is inside the link (by more than 1e-9); at an end, that point's own row holds.
The same lowest points are a run's recorded ``link_height`` and ``holder_height``
(:func:`lowest_chords`, in the compiled step's diagnostics).
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from dvqp.errors import ParameterError
from dvqp.kinematics.state import KinematicState
from dvqp.limits.damper import DEFAULT_DECELERATION, Distances, VelocityDamper, fresh_rows
from dvqp.workspace import PartNames, link_ends
from dvqp.workspace.wiring import StepWiring, overrides
from solvers.jit import njit


class SurfaceHeight(VelocityDamper):
    """``h ≥ h_min`` for every body point and the lowest point of every body link (and of a
    rail arm's carriage link), one damper row each (``"point3/height"``, ``"link2/height"``,
    ``"carriage/height"``).

    Parameters
    ----------
    min_height
        ``h_min``, m (finite).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "height"
    quantity = "height"
    IN_EVERY_SCENE = True
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "min_height": "min_height",
        "damper_gain": "gain",
    }

    def __init__(
        self,
        min_height: float = 0.0,
        gain: float = 0.5,
        deceleration: float = DEFAULT_DECELERATION,
    ) -> None:
        super().__init__(gain, deceleration)
        self.min_height = finite("min_height", min_height)

    @property
    def safe(self) -> float:
        """``h_min``, m."""
        return self.min_height

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``"point1/height"``, ... one per body point, then per body link (and the carriage
        link if the arm has a rail), by their ``names``."""
        k = names.k
        links = [names.links[i] for i in body_chords(k, names)]
        return (*(f"{p}/height" for p in names.points[:k]), *(f"{a}/height" for a in links))

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """The body points' curve and the link chords'."""
        return [("height", "body points", slice(0, k)), ("height", "link chords", slice(k, count))]

    def distances(self, state: KinematicState) -> Distances:
        """The rows its kernels write at ``state``: the body points', then the chords'."""
        return height_rows(self, state, 0, state.k, body_chords(state.k, state.part_names))

    def join(self, step: StepWiring) -> None:
        """Rows of the k body points, then of the chords of the body links (and the carriage
        link), measured by :func:`height_distances` and :func:`chord_heights`."""
        if overrides(self, SurfaceHeight, "distances", "kernel"):
            return super().join(step)
        k = step.plan.k
        join_heights(self, step, 0, k, body_chords(k, step.plan.names))
        return None


class ProbeHeight(VelocityDamper):
    """``h ≥ floor`` for the probe (the tool point) and the lowest point of its holder, two
    damper rows (``"probe/height"``, ``"holder/height"``).

    The body points keep ``min_height`` (:class:`SurfaceHeight`); the probe, which inspects the
    surface, only has to stay out of the pipe wall.

    Parameters
    ----------
    floor
        Lowest probe height, m (default 0: touching the surface is allowed).
    gain
        ``γ`` in (0, 1].
    deceleration
        ``a``, m/s².
    """

    name = "probe_height"
    quantity = "height"
    IN_EVERY_SCENE = True
    SCENE_KEYS: ClassVar[dict[str, str]] = {
        "damper_deceleration": "deceleration",
        "damper_gain": "gain",
    }

    def __init__(
        self, floor: float = 0.0, gain: float = 0.5, deceleration: float = DEFAULT_DECELERATION
    ) -> None:
        super().__init__(gain, deceleration)
        self.floor = finite("floor", floor)

    @property
    def safe(self) -> float:
        """``floor``, m."""
        return self.floor

    def labels(self, names: PartNames) -> tuple[str, ...]:
        """``("probe/height", "holder/height")``, by the parts' ``names``."""
        return (f"{names.probe}/height", f"{names.holder}/height")

    def series(self, count: int, k: int, rail: bool) -> list[tuple[str, str, slice | list[int]]]:
        """The probe's curve and its holder's."""
        return [("height", "probe", [0]), ("height", "holder", [1])]

    def distances(self, state: KinematicState) -> Distances:
        """The rows its kernels write at ``state``: the probe's, then its holder's chord."""
        return height_rows(self, state, state.k, 1, [state.k - 1])

    def join(self, step: StepWiring) -> None:
        """Rows of the probe (guarded point k) and of its holder's chord (link k − 1)."""
        if overrides(self, ProbeHeight, "distances", "kernel"):
            return super().join(step)
        k = step.plan.k
        join_heights(self, step, k, 1, [k - 1])
        return None


def body_chords(k: int, names: PartNames) -> list[int]:
    """The guarded links whose chords keep ``min_height``: the body links and a rail arm's
    carriage link (a base link keeps the surface: :class:`~dvqp.limits.BaseHeight`)."""
    return [*range(k - 1), *([k] if names.rail and not names.base else [])]


def height_rows(
    limit: VelocityDamper, state: KinematicState, first: int, points: int, chords: list[int]
) -> Distances:
    """What :func:`height_distances` and :func:`chord_heights` write for ``limit`` at
    ``state`` (the rows :func:`join_heights` reserves)."""
    k, rail = state.k, state.rail
    distance, gradient, usable = fresh_rows(points + len(chords), state.n)
    guarded, jacobians = state.guarded, state.guarded_jacobians
    height_distances(guarded, jacobians, first, points, 0, distance, gradient, usable)
    table = np.array([(points + c, link) for c, link in enumerate(chords)], dtype=np.int64)
    ends, labels = link_ends(k, rail), limit.labels(state.part_names)
    chord_heights(
        guarded,
        state.origins,
        state.frame_jacobians,
        ends,
        state.radius,
        table.reshape(-1, 2),
        distance,
        gradient,
        usable,
    )
    return Distances(distance, gradient, limit.safe, lambda: labels, usable)


def join_heights(
    limit: VelocityDamper, step: StepWiring, first: int, points: int, chords: list[int]
) -> None:
    """Damper rows of guarded points ``first .. first + points − 1``, then of the lowest point
    of each guarded link in ``chords``."""
    start = step.damper(limit, points + len(chords), limit.labels(step.plan.names))
    step.measures["heights"].append((start, first, points))
    step.measures["chords"].extend((start + points + c, link) for c, link in enumerate(chords))


def finite(name: str, value: float) -> float:
    """``value`` as a float, or ParameterError(name) unless it is finite."""
    if not np.isfinite(value):
        raise ParameterError(name, "must be finite")
    return float(value)


@njit(separate=True)
def height_distances(guarded, jacobians, first, count, start, distance, gradient, usable) -> None:  # type: ignore[no-untyped-def]
    """Heights ``h`` (m) and ``∂h/∂Q`` of the guarded points ``first .. first + count − 1``
    (``guarded`` (k+1, 3), ``jacobians`` (k+1, 3, n)), from row ``start``."""
    for m in range(count):
        p, r = first + m, start + m
        distance[r], usable[r] = guarded[p, 2], True
        for c in range(gradient.shape[1]):
            gradient[r, c] = jacobians[p, 2, c]


@njit
def chord_low(guarded, origins, a, b, radius):  # type: ignore[no-untyped-def]
    """``(h, t*, inside, u_x, u_y)`` of the lowest point of the chord joining guarded frames
    ``a`` and ``b`` (``origins`` (m, 3), m): its height (m; where the lowest point is an end,
    that end's own, ``guarded[., 2]``, so that it ties exactly with the end's row), its
    parameter, whether it lies inside the link (by more than 1e-9: not at an end, nor within
    round-off of one; the carriage link of a rail arm lies in the tangent plane at the rail
    point, t* = 0) and the unit xy direction from the pipe axis to it."""
    ax, ay = origins[a, 0], origins[a, 1]
    ex, ey = origins[b, 0] - ax, origins[b, 1] - ay
    length2 = ex * ex + ey * ey
    t = min(max(-(ax * ex + ay * ey) / length2, 0.0), 1.0) if length2 > 0.0 else 0.0
    px, py = ax + t * ex, ay + t * ey
    rho = math.hypot(px, py)
    inside = 1e-9 < t < 1.0 - 1e-9 and rho > 0.0
    h = rho - radius if inside else guarded[a if t < 0.5 else b, 2]
    return h, t, inside, px / max(rho, 1e-300), py / max(rho, 1e-300)


@njit(separate=True)
def chord_heights(
    guarded, origins, frame_jacobians, ends, radius, chords, distance, gradient, usable
) -> None:  # type: ignore[no-untyped-def]
    """The height (m) of the lowest point of guarded link ``chords[c, 1]`` (joining guarded
    frames ``ends[link]``; ``frame_jacobians`` (m, 6, n)) and its ``∂h/∂Q`` (see the module
    docstring) into row ``chords[c, 0]``, for each row c of ``chords`` (C, 2); a row applies
    where the lowest point is inside the link (:func:`chord_low`)."""
    for c in range(chords.shape[0]):
        r, a, b = chords[c, 0], ends[chords[c, 1], 0], ends[chords[c, 1], 1]
        distance[r], t, usable[r], ux, uy = chord_low(guarded, origins, a, b, radius)
        for q in range(gradient.shape[1]):
            jx = (1.0 - t) * frame_jacobians[a, 0, q] + t * frame_jacobians[b, 0, q]
            jy = (1.0 - t) * frame_jacobians[a, 1, q] + t * frame_jacobians[b, 1, q]
            gradient[r, q] = ux * jx + uy * jy


@njit(separate=True, python=True)  # Python calls it in every plan too
def lowest_chords(guarded, origins, ends, k, radius, skip):  # type: ignore[no-untyped-def]
    """``(h, i, h_holder)``: the lowest height (m) of the chords of the guarded links ``ends``
    (L, 2) other than the probe holder (link ``k − 1``) and link ``skip`` (−1: none): the
    body links and the carriage link, each at its lowest point (:func:`chord_low`); the link
    i that has it (−1: none); and the holder's lowest height (m; inf: none). A standing arm's
    base link is skipped in the body's figure: it keeps the surface, not ``min_height``
    (:class:`~dvqp.limits.BaseHeight`)."""
    low, which, holder = math.inf, -1, math.inf
    for i in range(ends.shape[0]):
        h = chord_low(guarded, origins, ends[i, 0], ends[i, 1], radius)[0]
        if i == k - 1:
            holder = h
        elif h < low and i != skip:
            low, which = h, i
    return low, which, holder


def lowest_link(state: KinematicState) -> tuple[float, str]:
    """The lowest height (m) of the body links' and the carriage link's chords at ``state``
    (:func:`lowest_chords`; not a standing arm's base link) and that link's name
    (``"link2"``, ``"carriage"``; inf and ``""`` without links)."""
    ends, skip = link_ends(state.k, state.rail), state.part_names.base_link
    low, which, _ = lowest_chords(
        np.array(state.guarded), np.array(state.origins), ends, state.k, state.radius, skip
    )
    return float(low), state.part_names.link(int(which)) if which >= 0 else ""
