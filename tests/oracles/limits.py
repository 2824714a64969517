"""What the limit tests check the compiled step against.

The distances each limit keeps are measured here independently of the step: clearances by
:func:`dvqp.geometry.proximity`, heights and frames by :meth:`KinematicState.compute`, the
distance between two links by a brute-force search on the segments. The formulas are the
NumPy ones dvqp had before its redesign (``git show 170077d:dvqp/limits/...``): the damper
rule ``damper_rhs``, the joint boxes (position, velocity, acceleration with braking), the
gradients of the obstacle rows and of the tilt, and the exact verification (``excess``:
``min(safe, value at the start) − value``, the worst by its ratio to the tolerance).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from dvqp import KinematicState, Robot
from dvqp.geometry import proximity, segment_distances
from dvqp.geometry.measure import ShapeArrays
from dvqp.geometry.proximity import measure as measure_chain
from dvqp.limits import (
    NO_EXCESS,
    AccelerationLimit,
    BaseHeight,
    Excess,
    JointPositionLimit,
    JointVelocityLimit,
    ObstacleDamper,
    ProbeHeight,
    SelfCollision,
    SurfaceHeight,
    TiltLimit,
    VelocityDamper,
)
from tests.common import central_difference

Array = NDArray[np.float64]


# -- the damper rule and the joint boxes (the old NumPy code) ------------------------------


def damper_rhs(
    distance: Array,
    safe: float | Array,
    gain: float,
    dt: float,
    depth: float,
    deceleration: float = math.inf,
) -> Array:
    """``γ/dt · (d − d_safe)``, capped above ``d_safe`` by the braking speed
    ``sqrt(2 a (d − d_safe))``; below it, a drift of at most ``δ`` is pulled back no faster
    than ``a·dt``, and deeper the distance may only not shrink (0)."""
    room = np.asarray(distance, dtype=float) - safe
    rhs = np.where(room < -depth, 0.0, gain / dt * room)
    if math.isinf(deceleration):
        return rhs
    return np.clip(rhs, -deceleration * dt, np.sqrt(2.0 * deceleration * np.maximum(room, 0.0)))


def position_box(q: Array, q_min: Array, q_max: Array, dt: float) -> tuple[Array, Array]:
    """``min((q_min − q)/dt, 0) ≤ Q̇ ≤ max((q_max − q)/dt, 0)``."""
    return np.minimum((q_min - q) / dt, 0.0), np.maximum((q_max - q) / dt, 0.0)


def braking(a: Array, dt: float, room: Array) -> Array:
    """The fastest speed toward a limit ``room`` away that still stops before it:
    ``Q̇ dt + Q̇²/(2a) = room``."""
    return -a * dt + np.sqrt((a * dt) ** 2 + 2.0 * a * np.maximum(room, 0.0))


def acceleration_box(limit: AccelerationLimit, q: Array, dt: float) -> tuple[Array, Array]:
    """``|Q̇ − Q̇_prev| ≤ q̈_max dt`` capped by the braking bounds (a joint that cannot brake in
    time any more keeps its position limit: ``lb = min(lb, ub)``)."""
    a, previous = limit.qdd_max, limit.previous
    ub = np.minimum(previous + a * dt, braking(a, dt, limit.q_max - q))
    lb = np.maximum(previous - a * dt, -braking(a, dt, q - limit.q_min))
    return np.minimum(lb, ub), ub


def joint_box(limits: Sequence[object], q: Array, dt: float) -> tuple[Array, Array]:
    """The box of every joint limit among ``limits``, intersected."""
    lb, ub = np.full(q.shape[0], -math.inf), np.full(q.shape[0], math.inf)
    for limit in limits:
        if isinstance(limit, JointPositionLimit):
            low, high = position_box(q, limit.q_min, limit.q_max, dt)
        elif isinstance(limit, JointVelocityLimit):
            low, high = -limit.qd_max, limit.qd_max
        elif isinstance(limit, AccelerationLimit):
            low, high = acceleration_box(limit, q, dt)
        else:
            continue
        lb, ub = np.maximum(lb, low), np.minimum(ub, high)
    return lb, ub


# -- distances measured independently of the step -------------------------------------------


def point_segment(p: Array, c: Array, d: Array) -> Array:
    """Distances of the points ``p`` (P, 3) to the segments ``c → d`` (P, 3)."""
    g = d - c
    t = np.clip(((p - c) * g).sum(-1) / np.maximum((g * g).sum(-1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(p - c - t[:, None] * g, axis=-1)  # type: ignore[no-any-return]


def segment_distance(a: Array, b: Array, c: Array, d: Array) -> tuple[Array, Array]:
    """Brute force: the smallest distance between the segments ``a → b`` and ``c → d`` (each
    (P, 3)) and the ``s`` of its point on ``a → b``, by a golden-section search on ``s`` of the
    exact point-to-segment distance (convex in ``s``)."""
    lo, hi = np.zeros(a.shape[0]), np.ones(a.shape[0])
    ratio = 0.5 * (math.sqrt(5.0) - 1.0)

    def f(s: Array) -> Array:
        return point_segment(a + s[:, None] * (b - a), c, d)

    for _ in range(90):
        x1, x2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
        left = f(x1) <= f(x2)
        hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
    s = 0.5 * (lo + hi)
    ends = np.stack([f(np.zeros_like(s)), f(np.ones_like(s)), f(s)])
    best = ends.argmin(axis=0)
    return ends.min(axis=0), np.choose(best, [np.zeros_like(s), np.ones_like(s), s])


def guarded_links(k: int, rail: bool) -> Array:
    """The guarded links as point indices, written out: body links ``i → i+1``, the holder
    ``k−1 → k`` (last body point to the probe), the carriage ``k+1 → 0`` (rail point to body
    point 1)."""
    body = [(i, i + 1) for i in range(k - 1)]
    return np.array([*body, (k - 1, k), *([(k + 1, 0)] if rail else [])], np.int64)


def link_pairs(k: int, rail: bool = False) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs ``(i, j)``, ``i < j``, of guarded links with no point in common, listed."""
    ends = guarded_links(k, rail)
    pairs = [
        (i, j)
        for i in range(len(ends))
        for j in range(i + 1, len(ends))
        if len({*ends[i], *ends[j]}) == 4
    ]
    return np.array([p[0] for p in pairs], np.int64), np.array([p[1] for p in pairs], np.int64)


def link_name(i: int, k: int, state: KinematicState | None = None) -> str:
    """``"link3"``; ``"holder"`` for guarded link k−1, ``"carriage"`` for k (a standing
    base's link: by the arm's own names, from ``state``)."""
    if state is not None and state.part_names.base and i == k:
        return state.part_names.link(i)
    return {k - 1: "holder", k: "carriage"}.get(i, f"link{i + 1}")


def point_name(i: int, k: int, state: KinematicState | None = None) -> str:
    """``"point3"``; ``"probe"`` for guarded point k, ``"rail"`` for k+1 (a standing base: by
    the arm's own names, from ``state``)."""
    if state is not None and state.part_names.base and i == k + 1:
        return state.part_names.point(i)
    return {k: "probe", k + 1: "rail"}.get(i, f"point{i + 1}")


def self_distances(origins: Array, k: int) -> Array:
    """Brute-force distances of every pair of guarded links with no common point, from the
    guarded frames' ``origins`` (m, 3) of an arm with k body points."""
    o = np.asarray(origins, dtype=float)
    rail = o.shape[0] > k + 1
    ends = guarded_links(k, rail)
    i, j = link_pairs(k, rail)
    return segment_distance(o[ends[i, 0]], o[ends[i, 1]], o[ends[j, 0]], o[ends[j, 1]])[0]


def tilt_cosine(state: KinematicState) -> tuple[float, Array]:
    """``u = cos θ`` of the probe axis to the radial direction and ``∂u/∂Q`` (the old NumPy
    formula: ``(a × r̂)ᵀ J_ω + aᵀ (P − r̂ r̂ᵀ) J_v / ρ``)."""
    t = state.k
    origin, axis, jac = state.origins[t], state.axes[t], state.frame_jacobians[t]
    rho = math.hypot(origin[0], origin[1])
    rx, ry = origin[0] / rho, origin[1] / rho
    ax, ay, az = axis.tolist()
    u = ax * rx + ay * ry
    cross = np.array([-az * ry, az * rx, ax * ry - ay * rx])
    tangential = np.array([(ax - u * rx) / rho, (ay - u * ry) / rho, 0.0])
    return u, cross @ jac[3:] + tangential @ jac[:3]


def tilt(state: KinematicState) -> float:
    """θ, rad in [0, π]: the angle between the probe's axis and the radial direction at the
    tool (guarded frame k)."""
    o, a = state.origins[state.k], state.axes[state.k]
    radial = np.array([o[0], o[1], 0.0]) / math.hypot(o[0], o[1])
    return math.acos(max(-1.0, min(1.0, float(a @ radial))))


def tilt_sine(state: KinematicState) -> float:
    """``sin θ``: the length of the probe axis' projection on the pipe's tangent plane."""
    o, a = state.origins[state.k], state.axes[state.k]
    u = (a[0] * o[0] + a[1] * o[1]) / math.hypot(o[0], o[1])
    return math.sqrt(max(1.0 - u * u, 0.0))


@dataclass(frozen=True)
class Measured:
    """Every distance a damper keeps at one state, in its rows' order.

    ``gradient`` is the old NumPy formula's ``∂d/∂Q`` (None where only finite differences
    check it); ``applies`` says which rows apply (gradient defined, below the reach).
    """

    value: Array
    gradient: Array | None
    safe: Array
    labels: tuple[str, ...]
    applies: NDArray[np.bool_]


def measure(
    limit: object,
    state: KinematicState,
    refine: Array | None = None,
    closest: tuple[float, float] | None = None,
) -> Measured:
    """The distances of one of dvqp's dampers, or of a user's :class:`VelocityDamper` (its
    own ``distances``), at ``state``; an obstacle damper's links refined below ``refine`` (per
    obstacle, m; default: its margin) and ``closest`` (see :func:`real_clearances`)."""
    k, n = state.k, state.n
    if type(limit) is ObstacleDamper:
        return _clearances(limit, state, refine, closest)
    if type(limit) in (SurfaceHeight, ProbeHeight, BaseHeight):
        return _heights(limit, state)
    if type(limit) is TiltLimit:
        u, du = tilt_cosine(state)
        d = tilt_sine(state)
        gradient = (-u / max(d, 1e-9)) * du
        return Measured(
            np.array([d]),
            gradient[None, :],
            np.array([limit.safe]),
            ("probe/tilt",),
            np.ones(1, bool),
        )
    if type(limit) is SelfCollision:
        i, j = link_pairs(k, state.rail)
        value = self_distances(np.array(state.origins), k)
        labels = tuple(f"{link_name(a, k)}/{link_name(b, k)}" for a, b in zip(i, j, strict=True))
        return Measured(
            value,
            None,
            np.full(value.shape, limit.margin),
            labels,
            value < limit.margin + limit.influence,
        )
    if isinstance(limit, VelocityDamper):
        found = limit.distances(state)
        value = np.asarray(found.value, dtype=float)
        labels = found.describe() if found.describe is not None else ()
        safe = np.broadcast_to(np.asarray(found.safe, dtype=float), value.shape).copy()
        return Measured(
            value, np.asarray(found.gradient).reshape(-1, n), safe, labels, value < limit.reach
        )
    raise TypeError(f"{type(limit).__name__} keeps no distances")


def chord_low(a: Array, b: Array, radius: float) -> tuple[float, float]:
    """Height (m) of the lowest point of the 3-D segment ``a → b`` and its parameter, by a
    ternary search of the convex ``‖xy(a + t (b − a))‖²`` (not dvqp's closed form)."""

    def rho2(t: float) -> float:
        p = a[:2] + t * (b[:2] - a[:2])
        return float(p @ p)

    lo, hi = 0.0, 1.0
    for _ in range(200):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        lo, hi = (lo, m2) if rho2(m1) <= rho2(m2) else (m1, hi)
    t = 0.5 * (lo + hi)
    return math.sqrt(rho2(t)) - radius, t


def _heights(limit: object, state: KinematicState) -> Measured:
    """The points' heights (their DV rows' gradient), then the lowest point of each link chord
    (body links and carriage for the body; the holder for the probe; gradient by differences)."""
    k, o = state.k, np.asarray(state.origins)
    body, base = type(limit) is SurfaceHeight, state.part_names.base
    points = list(range(k)) if body else [k]
    links = [*range(k - 1), *([k] if state.rail and not base else [])] if body else [k - 1]
    if type(limit) is BaseHeight:  # the base (lead point k + 1) and its link to point 1
        points, links = ([k + 1], [k]) if base else ([], [])
    ends = guarded_links(k, state.rail)

    def inside(a: Array, b: Array) -> bool:  # the lowest point inside the link: ρ² falls at a
        e = b[:2] - a[:2]  # and rises at b (by more than round-off)
        return bool(a[:2] @ e < -1e-9 * (e @ e) and b[:2] @ e > 1e-9 * (e @ e))

    def low(i: int) -> float:  # at an end: that end's own height (its row's)
        a, b = o[ends[i, 0]], o[ends[i, 1]]
        if inside(a, b):
            return chord_low(a, b, state.radius)[0]
        e = b[:2] - a[:2]
        return float(state.guarded[ends[i, 0] if a[:2] @ e >= -1e-9 * (e @ e) else ends[i, 1], 2])

    value = np.array([*state.guarded[points, 2], *(low(i) for i in links)])
    labels = (
        *(f"{point_name(i, k, state)}/height" for i in points),
        *(f"{link_name(i, k, state)}/height" for i in links),
    )

    applies = [inside(o[ends[i, 0]], o[ends[i, 1]]) for i in links]
    return Measured(
        value,
        None,
        np.full(value.shape, limit.safe),
        labels,  # type: ignore[attr-defined]
        np.array([True] * len(points) + applies),
    )


def bends(a: Array, b: Array) -> tuple[Array, Array]:
    """``(g, t*)`` of P 3-D links ``a → b`` (each (P, 3)): the largest (signed)
    ``θ(t) − t Δφ`` (rad; the DV image's departure from the straight DV segment, over R) and
    where, by sampling each link at 257 points, then bisecting its slope between the best
    sample's neighbours (not dvqp's quadratic). ``(0, 0)`` for a link that does not bend."""
    a, b = np.atleast_2d(a)[:, :2], np.atleast_2d(b)[:, :2]
    e = b - a
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    phi = np.arctan2(cross, (a * b).sum(axis=1))

    def g(u: Array) -> Array:  # (P, S) at parameters u (P, S)
        x, y = a[:, :1] + u * e[:, :1], a[:, 1:] + u * e[:, 1:]
        turn = np.arctan2(a[:, :1] * y - a[:, 1:] * x, a[:, :1] * x + a[:, 1:] * y)
        return turn - u * phi[:, None]  # type: ignore[no-any-return]

    def slope(u: Array) -> Array:  # θ'(u) − Δφ, (P,)
        x, y = a[:, 0] + u * e[:, 0], a[:, 1] + u * e[:, 1]
        return (x * e[:, 1] - y * e[:, 0]) / (x * x + y * y) - phi  # type: ignore[no-any-return]

    t = np.broadcast_to(np.linspace(0.0, 1.0, 257), (a.shape[0], 257))
    sampled = g(t)
    i = np.clip(np.argmax(np.abs(sampled), axis=1), 1, 255)
    lo, hi = t[0, i - 1], t[0, i + 1]
    rising = slope(lo) > 0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        same = (slope(mid) > 0) == rising
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    u = 0.5 * (lo + hi)
    found = g(u[:, None])[:, 0]
    flat = np.abs(sampled).max(axis=1) < 1e-15
    return np.where(flat, 0.0, found), np.where(flat, 0.0, u)


def bend(a: Array, b: Array) -> tuple[float, float]:
    """:func:`bends` of one link."""
    g, t = bends(a, b)
    return float(g[0]), float(t[0])


def _turn(o: Array, jac: Array, a: int, b: int, t: float) -> Array:
    """``∂φ/∂Q`` (n,) of the point at ``t`` on the 3-D link from frame a to b, ``φ`` its angle
    around the pipe axis: ``(x ∂y − y ∂x)/ρ²``."""
    p, dp = (1 - t) * o[a] + t * o[b], (1 - t) * jac[a, :3] + t * jac[b, :3]
    return (p[0] * dp[1] - p[1] * dp[0]) / (p[0] ** 2 + p[1] ** 2)  # type: ignore[no-any-return]


def dv_from(a: Array, la: float, p: Array, radius: float) -> Array:
    """``[l, z]`` (m) of 3-D points ``p`` (P, 3), ``l`` continued from ``a``'s (``la``)."""
    x, y = a[0], a[1]
    turn = np.arctan2(x * p[:, 1] - y * p[:, 0], x * p[:, 0] + y * p[:, 1])
    return np.column_stack([la + radius * turn, p[:, 2]])


def closest_parts(
    obstacles: Sequence[object], frames: object, radius: float
) -> tuple[float, float]:
    """Above the arm's closest part to any of ``obstacles``, and above the probe's or its
    holder's (m): points exactly, links as their straight DV segments plus their bend."""
    k, o = frames.k, np.asarray(frames.origins)  # type: ignore[attr-defined]
    ends = guarded_links(k, frames.rail)  # type: ignore[attr-defined]
    near = measure_chain(tuple(obstacles), np.asarray(frames.guarded), 2 * math.pi * radius, ends)  # type: ignore[attr-defined]
    upper = near.link_distance + radius * np.abs(bends(o[ends[:, 0]], o[ends[:, 1]])[0])[None]
    holder = int(np.flatnonzero(ends[:, 1] == k)[0])
    arm = min(near.point_distance.min(initial=math.inf), upper.min(initial=math.inf))
    probe = min(
        near.point_distance[:, k].min(initial=math.inf), upper[:, holder].min(initial=math.inf)
    )
    return float(arm), float(probe)


def first_pieces(t: float, bend: float) -> Array:
    """The pieces dvqp's halving starts from (``dvqp.geometry.link_pieces``): the halving's
    piece (at ``k / 2ⁿ``) that holds ``t``, the straight link's closest point, short enough for
    its bend (about the link's ``bend`` (m) times the square of its length) to be within
    5 µm with 30 % to spare, a piece as short either side, and the rest of the link."""
    width = 0.7 * math.sqrt(0.5e-5 / bend)
    cuts = 2.0 ** max(math.ceil(-math.log2(width)), 0) if width < 1.0 else 1.0
    at = min(math.floor(t * cuts), cuts - 1.0)
    cut = [0.0, *(min(max((at + k) / cuts, 0.0), 1.0) for k in (-1, 0, 1, 2)), 1.0]
    return np.array([[a, b] for a, b in itertools.pairwise(cut) if b > a])


def real_clearances(
    obstacles: Sequence[object],
    frames: object,
    radius: float,
    refine: Array,
    closest: tuple[float, float] | None = None,
    jac: Array | None = None,
) -> tuple[Array, Array, Array, Array]:
    """Each link's clearance to each obstacle as dvqp defines it (``dvqp.geometry.real_links``),
    rebuilt from other parts: the straight pieces' distances by
    :func:`dvqp.geometry.segment_distances`, their bends by :func:`bend` (sampling and
    bisection), the rule written out again: a pair in pieces where its bound is below
    ``refine`` (J,) of its obstacle, m, or below ``closest`` (:func:`closest_parts` of every
    obstacle of the step; default: of these), halved as dvqp halves them from
    :func:`first_pieces`. Returns the
    clearance (J, L), the link parameter of its closest point (J, L), whether its normal is
    defined (J, L), and with ``jac`` (the frames' Jacobians (m, 6, n)) its gradient (J, L, n) by the
    envelope formula written in NumPy. ``frames``: a state or Pinocchio's frames (``origins``,
    ``guarded`` (m, 3), ``k``, ``rail``)."""
    k, o = frames.k, np.asarray(frames.origins)  # type: ignore[attr-defined]
    guarded, period = np.asarray(frames.guarded), 2.0 * math.pi * radius  # type: ignore[attr-defined]
    ends = guarded_links(k, frames.rail)  # type: ignore[attr-defined]
    shapes = tuple(obstacles)
    own = ~ShapeArrays.of(shapes, period).compiled  # shapes of your own: one piece
    straight = measure_chain(shapes, guarded, period, ends)
    whole = radius * np.abs(bends(o[ends[:, 0]], o[ends[:, 1]])[0])
    value = straight.link_distance - whole[None]
    arm, probe = closest_parts(shapes, frames, radius) if closest is None else closest
    t, normal = straight.link_t.copy(), straight.link_normal.copy()
    piece = np.zeros((*value.shape, 2))  # [t0, t1] of the closest piece
    piece[..., 1] = 1.0
    for i, (a, b) in enumerate(ends):
        for j, shape in enumerate(shapes):
            reported = probe if b == k else arm
            if 2 * whole[i] <= 1e-5 or own[j]:
                continue
            if not (value[j, i] < refine[j] + 2 * whole[i] or value[j, i] < reported):
                continue
            live, upper, best = first_pieces(t[j, i], whole[i]), math.inf, math.inf
            while live.size:  # the pieces, halved a level at a time (branch and bound)
                p0 = o[a][None] + live[:, :1] * (o[b] - o[a])[None]
                p1 = o[a][None] + live[:, 1:] * (o[b] - o[a])[None]
                lz0 = dv_from(o[a], guarded[a, 0], p0, radius)
                lz1 = dv_from(o[a], guarded[a, 0], p1, radius)
                d, s, nn = segment_distances([shape], lz0, lz1, period)
                d, s, nn = d[0], s[0], nn[0]
                bent = radius * np.abs(bends(p0, p1)[0])
                upper = min(upper, float((d + bent).min()))
                final = 2 * bent <= 1e-5
                for c in np.flatnonzero(final):
                    if d[c] - bent[c] < best:
                        best = d[c] - bent[c]
                        t0, t1 = live[c]
                        value[j, i], normal[j, i] = best, nn[c]
                        t[j, i], piece[j, i] = t0 + s[c] * (t1 - t0), (t0, t1)
                halve = ~final & (d - bent < min(upper, best))
                middle = live[halve].mean(axis=1)
                live = np.stack([live[halve, 0], middle, middle, live[halve, 1]], axis=1)
                live = live.reshape(-1, 2)
    if jac is None:
        return value, t, (normal != 0.0).any(axis=-1), np.zeros((*value.shape, 0))
    gradient = np.zeros((*value.shape, jac.shape[2]))
    pairs = list(np.ndindex(value.shape))
    start = np.array(
        [(1 - piece[j, i, 0]) * o[ends[i, 0]] + piece[j, i, 0] * o[ends[i, 1]] for j, i in pairs]
    ).reshape(-1, 3)
    stop = np.array(
        [(1 - piece[j, i, 1]) * o[ends[i, 0]] + piece[j, i, 1] * o[ends[i, 1]] for j, i in pairs]
    ).reshape(-1, 3)
    piece_bends = bends(start, stop) if pairs else (np.zeros(0), np.zeros(0))
    for r, (j, i) in enumerate(pairs):
        a, b = ends[i]
        t0, t1 = piece[j, i]
        s = (t[j, i] - t0) / (t1 - t0)
        turn0, turn1 = _turn(o, jac, a, b, t0), _turn(o, jac, a, b, t1)
        z0, z1 = ((1 - x) * jac[a, 2] + x * jac[b, 2] for x in (t0, t1))
        gradient[j, i] = normal[j, i, 0] * radius * ((1 - s) * turn0 + s * turn1) + normal[
            j, i, 1
        ] * ((1 - s) * z0 + s * z1)
        g, w = piece_bends[0][r], piece_bends[1][r]
        if g != 0.0:
            at = _turn(o, jac, a, b, t0 + w * (t1 - t0)) - (1 - w) * turn0 - w * turn1
            gradient[j, i] -= radius * math.copysign(1.0, g) * at
    return value, t, (normal != 0.0).any(axis=-1), gradient


def _clearances(
    limit: ObstacleDamper,
    state: KinematicState,
    refine: Array | None,
    closest: tuple[float, float] | None = None,
) -> Measured:
    """Every (point, obstacle) then every (link, obstacle) clearance, obstacle-major, with the
    old NumPy gradient ``n · ∂p/∂Q`` for the points; the links' real clearances
    (:func:`real_clearances`, refined below the damper's margin)."""
    k, n = state.k, state.n
    count = len(limit.obstacles)
    if count == 0:
        return Measured(np.zeros(0), np.zeros((0, n)), np.zeros(0), (), np.zeros(0, bool))
    points = proximity(state, limit.obstacles).points
    jac = np.array(state.guarded_jacobians[:, :3, :])  # (m, 3, n): l, z, h
    point_rows = np.einsum("jpc,pcn->jpn", points.normal, jac)  # (J, m, n)
    if refine is None:
        refine = np.full(count, limit.margin)
    links, t, normal_ok, link_rows = real_clearances(
        limit.obstacles, state, state.radius, refine, closest, np.asarray(state.frame_jacobians)
    )
    ends = guarded_links(k, state.rail)
    point_ok = (points.normal != 0.0).any(axis=-1)
    link_ok = normal_ok & (t > 0.0) & (t < 1.0)
    value = np.concatenate([points.distance.ravel(), links.ravel()])
    gradient = np.concatenate([point_rows.reshape(-1, n), link_rows.reshape(-1, n)])
    usable = np.concatenate([point_ok.ravel(), link_ok.ravel()])
    labels = (
        *(f"{point_name(i, k)}/obstacles[{j}]" for j in range(count) for i in range(len(jac))),
        *(f"{link_name(i, k)}/obstacles[{j}]" for j in range(count) for i in range(len(ends))),
    )
    return Measured(
        value,
        gradient,
        np.full(value.shape, limit.margin),
        labels,
        usable & (value < limit.influence),
    )


def distance_jacobian(
    limit: object,
    robot: Robot,
    q: Array,
    radius: float,
    eps: float = 1e-7,
    refine: Array | None = None,
    union: Sequence[object] | None = None,
) -> Array:
    """Central differences of every distance of ``limit`` at ``q`` (p, n)."""

    def values(v: Array) -> Array:
        state = KinematicState.compute(robot, v, radius)
        closest = None if union is None else closest_parts(union, state, radius)
        return measure(limit, state, refine, closest).value

    return central_difference(values, np.asarray(q, dtype=float), eps)  # type: ignore[no-any-return]


# -- the exact verification ------------------------------------------------------------------


@dataclass(frozen=True)
class Verified:
    """The exact values a limit is verified on, with their safe values and labels."""

    values: Array
    safe: Array
    tolerance: float
    labels: tuple[str, ...]
    quantity: str
    unit: str


def verified(limit: object, state: KinematicState) -> Verified | None:
    """The values ``limit`` is verified on at ``state`` (None: nothing to verify)."""
    if type(limit) is JointPositionLimit:
        q = np.array(state.q)
        names = tuple(f"joint{i + 1}" for i in range(state.n))
        return Verified(
            np.concatenate([limit.q_max - q, q - limit.q_min]),
            np.zeros(2 * state.n),
            limit.tolerance,
            names + names,
            "joint position",
            "rad",
        )
    if not isinstance(limit, VelocityDamper):
        return None
    if type(limit) is TiltLimit:
        if limit.min_tilt == 0.0:
            return None
        angle = math.asin(min(tilt_sine(state), 1.0))
        return Verified(
            np.array([angle]),
            np.array([limit.min_tilt]),
            limit.tolerance,
            ("probe/tilt",),
            "tilt",
            "rad",
        )
    found = measure(limit, state)
    if found.value.shape[0] == 0:
        return None
    labels = found.labels or tuple(f"{limit.name}{i + 1}" for i in range(found.value.shape[0]))
    return Verified(found.value, found.safe, limit.tolerance, labels, limit.quantity, limit.unit)


def worst_excess(limits: Sequence[object], start: KinematicState, state: KinematicState) -> Excess:
    """The old rule: per value ``over = min(safe, value at start) − value``; the worst is the
    largest ``over / tolerance`` (a NaN first), the joint room ahead of the dampers."""
    worst, worst_ratio = NO_EXCESS, -math.inf
    ordered = sorted(limits, key=lambda limit: type(limit) is not JointPositionLimit)
    if sum(type(limit) is JointPositionLimit for limit in limits) > 1:
        raise ValueError("the oracle takes one JointPositionLimit")
    for limit in ordered:
        at_start, now = verified(limit, start), verified(limit, state)
        if now is None or at_start is None:
            continue
        over = np.minimum(at_start.safe, at_start.values) - now.values
        ratio = over / now.tolerance
        i = int(np.argmax(np.where(np.isnan(ratio), np.inf, ratio)))
        if not ratio[i] > worst_ratio and not math.isnan(ratio[i]):
            continue
        label = now.labels[i] if over[i] > 0.0 else ""
        if type(limit) is JointPositionLimit:
            q = float(state.q[i % state.n])
            bound = q - over[i] if i < state.n else q + over[i]
            found = Excess(
                float(over[i]), now.tolerance, label, now.quantity, now.unit, q, float(bound)
            )
        else:
            found = Excess(
                float(over[i]),
                now.tolerance,
                label,
                now.quantity,
                now.unit,
                float(now.values[i]),
                float(over[i] + now.values[i]),
            )
        worst, worst_ratio = found, float(ratio[i])
        if math.isnan(ratio[i]):
            break
    return worst


def assert_excess(found: Excess, want: Excess, atol: float = 1e-12) -> None:
    """Two excesses agree: values to ``atol``, words exactly."""
    assert (found.label, found.quantity, found.unit) == (want.label, want.quantity, want.unit)
    assert found.tolerance == want.tolerance
    for a, b in ((found.value, want.value), (found.actual, want.actual), (found.bound, want.bound)):
        assert a == b or abs(a - b) <= atol, (found, want)
