"""Independent oracles for the resolution, step and run tests (none of dvqp's step code).

- :func:`eq18`, :func:`kkt`: the baseline's step as the paper writes it (eq. 18, weighted), and
  the minimiser of the equality-constrained QP from its KKT system; :func:`nested`: strict
  priorities by null-space bases (SVD);
- :func:`frames`: the guarded frames, their developed-view coordinates and the tool's from
  Pinocchio (not dvqp's compiled kinematics);
- :func:`point_distances`, :func:`link_distances`: every shape's signed distance in NumPy (a
  link by dense sampling: brute force);
- :func:`segment_distance`: the exact distance of two 3-D segments, by the minimum of the
  convex quadratic over the square's interior and its four edges (not Ericson's clamping);
- :func:`verified_values`, :func:`worst_excess`: the exact values a run verifies after each
  step, and the worst excess of a state, from the above;
- :func:`kkt_residual`: an optimality certificate of a QP's answer (its KKT conditions, the
  multipliers found by non-negative least squares of our own).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numba import njit
from numpy.typing import NDArray

from dvqp import Robot
from dvqp.geometry.shapes import Band, Circle, Inlet, Polygon, Shape
from dvqp.limits import (
    JointPositionLimit,
    ObstacleDamper,
    ProbeHeight,
    SelfCollision,
    SurfaceHeight,
    TiltLimit,
)
from tests.oracles.geometry import inlet_points
from tests.oracles.limits import (
    chord_low,
    closest_parts,
    guarded_links,
    link_pairs,
    real_clearances,
)

Array = NDArray[np.float64]


# -- the step ---------------------------------------------------------------------------------


def eq18(
    jac: Array, xdot: Array, g: Array, weights: Array | None = None, damping: float = 0.0
) -> Array:
    """Eq. 18 in its weighted form, literally: ``J⁺ ẋ + (I − J⁺ J) W⁻¹ g`` with
    ``J⁺ = W⁻¹ Jᵀ (J W⁻¹ Jᵀ + μ² I)⁻¹`` (``W = I`` by default)."""
    n, m = jac.shape[1], jac.shape[0]
    w_inv = np.diag(np.ones(n) if weights is None else 1.0 / np.asarray(weights))
    jp = w_inv @ jac.T @ np.linalg.inv(jac @ w_inv @ jac.T + damping**2 * np.eye(m))
    return jp @ xdot + (np.eye(n) - jp @ jac) @ w_inv @ g  # type: ignore[no-any-return]


def kkt(jac: Array, xdot: Array, g: Array, metric: Array) -> Array:
    """The minimiser of ``½ Q̇ᵀ M Q̇ − gᵀ Q̇`` subject to ``J Q̇ = ẋ``, from its KKT system."""
    n, m = jac.shape[1], jac.shape[0]
    system = np.block([[metric, jac.T], [jac, np.zeros((m, m))]])
    return np.linalg.solve(system, np.concatenate([g, xdot]))[:n]  # type: ignore[no-any-return]


def nested(
    levels: Sequence[tuple[Array, Array]],
    g: Array,
    weights: Array,
    row_weights: Sequence[Array] | None = None,
) -> Array:
    """Strict priorities without inequalities, by null-space bases (SVD), not by dvqp's
    recursion: in ``y = W^½ Q̇`` each level ``(J_k, v_k)`` is solved in least squares within the
    basis ``Z`` of what the levels above leave free (its rows weighed by ``row_weights[k]``,
    ``Σ w_i r_i²``), ``Z`` then shrinks to the part of it that ``J_k`` does not move, and
    ``W^-½ g`` is added projected on the last ``Z``: the lexicographic minimiser of the levels'
    residuals, then of ``½ Q̇ᵀWQ̇ − gᵀQ̇``."""
    root = np.sqrt(np.asarray(weights, dtype=float))
    n = root.shape[0]
    y, basis = np.zeros(n), np.eye(n)
    for k, (jac, v) in enumerate(levels):
        if row_weights is not None:
            scale = np.sqrt(np.asarray(row_weights[k], dtype=float))
            jac, v = jac * scale[:, None], v * scale
        moved = (jac / root) @ basis  # J W^-½ Z
        z = np.linalg.lstsq(moved, v - (jac / root) @ y, rcond=1e-12)[0]
        y = y + basis @ z
        _, s, vt = np.linalg.svd(moved)
        rank = int(np.sum(s > 1e-10 * max(s.max(initial=0.0), 1.0)))
        basis = basis @ vt[rank:].T
    y = y + basis @ (basis.T @ (g / root))
    return y / root  # type: ignore[no-any-return]


# -- kinematics -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Frames:
    """The guarded frames of one configuration, from Pinocchio.

    ``origins``, ``axes`` (m, 3): the k body points, the tool, the rail point (if any), base
    frame; ``guarded`` (m, 3): ``[l, z, h]`` with ``l = R atan2(y, x)``, ``h = ρ − R``;
    ``tool`` (4,): ``[l, z, h, α]`` with ``α = atan2(a_z, (O_x a_y − O_y a_x)/ρ)``.
    """

    origins: Array
    axes: Array
    guarded: Array
    tool: Array
    k: int

    @property
    def rail(self) -> bool:
        """Whether the arm's rail point is among the frames (after the tool)."""
        return self.origins.shape[0] > self.k + 1


def frames(robot: Robot, q: Array, radius: float) -> Frames:
    """The guarded frames of ``q`` from Pinocchio's forward kinematics."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, np.asarray(q, dtype=float))
    origins = np.array([data.oMf[f].translation for f in robot.frame_ids])
    axes = np.array([data.oMf[f].rotation[:, 2] for f in robot.frame_ids])
    rho = np.hypot(origins[:, 0], origins[:, 1])
    guarded = np.column_stack(
        [radius * np.arctan2(origins[:, 1], origins[:, 0]), origins[:, 2], rho - radius]
    )
    k = robot.n_points
    o, a = origins[k], axes[k]
    alpha = math.atan2(a[2], (o[0] * a[1] - o[1] * a[0]) / rho[k])
    return Frames(origins, axes, guarded, np.array([*guarded[k], alpha]), k)


def wrapped(dl: Array, period: float) -> Array:
    """``dl`` wrapped into ``[−period/2, period/2)``."""
    return (np.asarray(dl) + 0.5 * period) % period - 0.5 * period  # type: ignore[no-any-return]


def tilt(f: Frames) -> float:
    """The probe axis' angle from the radial direction at the tool, rad, in [0, π]."""
    o, a = f.origins[f.k], f.axes[f.k]
    radial = np.array([o[0], o[1], 0.0]) / math.hypot(o[0], o[1])
    return math.acos(max(-1.0, min(1.0, float(a @ radial))))


# -- distances --------------------------------------------------------------------------------


@njit(cache=True)
def _polygon_loop(vl: Array, vz: Array, pl: Array, pz: Array, out: Array) -> None:
    """Distance of each point to the nearest edge of the closed polygon ``(vl, vz)``,
    negative inside (a crossing count along +l): a plain double loop."""
    count = vl.shape[0]
    for p in range(pl.shape[0]):
        best, inside = np.inf, False
        for e in range(count):
            al, az, bl, bz = vl[e], vz[e], vl[(e + 1) % count], vz[(e + 1) % count]
            el, ez = bl - al, bz - az
            t = ((pl[p] - al) * el + (pz[p] - az) * ez) / (el * el + ez * ez)
            t = min(max(t, 0.0), 1.0)
            best = min(best, math.hypot(pl[p] - al - t * el, pz[p] - az - t * ez))
            if (az > pz[p]) != (bz > pz[p]) and pl[p] < al + (pz[p] - az) / (bz - az) * el:
                inside = not inside
        out[p] = -best if inside else best


def _polygon(vertices: Array, p: Array, period: float) -> Array:
    """Signed distance of points ``p`` (m, 2) to a simple polygon, l measured from the
    vertices' mean (wrapped)."""
    ref = vertices[:, 0].mean()
    out = np.empty(p.shape[0])
    _polygon_loop(
        np.ascontiguousarray(vertices[:, 0] - ref),
        np.ascontiguousarray(vertices[:, 1]),
        np.ascontiguousarray(wrapped(p[:, 0] - ref, period)),
        np.ascontiguousarray(p[:, 1]),
        out,
    )
    return out


def with_height(footprint: Array, h: Array, height: float) -> Array:
    """Signed distance (m) to a footprint extruded from the surface up to ``height``, from the
    footprint's plane distance and the points' heights: case by case (beside and below the
    top, above the top face, past the top edge, inside the solid)."""
    above = h - height
    out = np.array(footprint, dtype=np.float64)
    over = (footprint <= 0.0) & (above > 0.0)
    corner = (footprint > 0.0) & (above > 0.0)
    inside = (footprint <= 0.0) & (above <= 0.0)
    out[over] = above[over]
    out[corner] = np.sqrt(footprint[corner] ** 2 + above[corner] ** 2)
    out[inside] = np.maximum(footprint[inside], above[inside])
    return out


def point_distances(obstacles: Sequence[Shape], p: Array, period: float) -> Array:
    """Signed distance (m) of points ``p`` to every obstacle: (J, m). ``p`` (m, 2) ``[l, z]``:
    to the footprints (as if every obstacle were unbounded); (m, 3) ``[l, z, h]``: to each
    obstacle's solid (:func:`with_height`, for an obstacle with a height)."""
    out = [_footprint_distance(shape, p, period) for shape in obstacles]
    if p.shape[1] == 3:
        out = [
            with_height(d, p[:, 2], shape.height) if math.isfinite(shape.height) else d
            for d, shape in zip(out, obstacles, strict=True)
        ]
    return np.array(out).reshape(len(out), p.shape[0])


def _footprint_distance(shape: Shape, p: Array, period: float) -> Array:
    """Signed distance (m) of points ``p`` (m, ≥ 2) ``[l, z, ...]`` to a footprint: (m,)."""
    if type(shape) is Circle:
        d = np.column_stack([wrapped(p[:, 0] - shape.center[0], period), p[:, 1] - shape.center[1]])
        return np.linalg.norm(d, axis=1) - shape.radius  # type: ignore[no-any-return]
    if type(shape) is Band:
        return np.maximum(shape.z_min - p[:, 1], p[:, 1] - shape.z_max)  # type: ignore[no-any-return]
    if type(shape) is Polygon:
        return _polygon(np.asarray(shape.vertices), p, period)
    if type(shape) is Inlet:  # the exact intersection curve, searched in NumPy
        lz = np.ascontiguousarray(p[:, :2])
        return inlet_points(shape.center, shape.radius, shape.pipe_radius, lz, period)[0]  # type: ignore[no-any-return]
    raise TypeError(f"no oracle for {type(shape).__name__}")


def link_distances(
    obstacles: Sequence[Shape], guarded: Array, period: float, k: int, samples: int = 401
) -> Array:
    """Signed distance (m) of every guarded link (of an arm with k body points) to every
    obstacle, brute force: each link sampled at ``samples`` points, then again at ``samples``
    points between the neighbours of each obstacle's closest sample: (J, L)."""
    lz = guarded[:, :2]
    coarse = np.linspace(0.0, 1.0, samples)
    step = coarse[1]
    ends = guarded_links(k, lz.shape[0] > k + 1)
    out = np.zeros((len(obstacles), len(ends)))
    for i, (first, last) in enumerate(ends):
        a, b = lz[first], lz[last].copy()
        b[0] = a[0] + wrapped(b[0] - a[0], period)
        d = point_distances(obstacles, a + coarse[:, None] * (b - a), period)
        for j, shape in enumerate(obstacles):
            t = coarse[np.argmin(d[j])]
            fine = np.linspace(max(t - step, 0.0), min(t + step, 1.0), samples)
            near = point_distances([shape], a + fine[:, None] * (b - a), period)
            out[j, i] = min(d[j].min(), near.min())
    return out


def segment_distance(a: Array, b: Array, c: Array, d: Array) -> float:
    """The distance of 3-D segments ``ab`` and ``cd``: the smallest of ``‖a + s u − c − t v‖``
    at the interior stationary point (if in the unit square) and on the square's four edges."""
    u, v, r = b - a, d - c, a - c
    uu, vv, uv, ur, vr = u @ u, v @ v, u @ v, u @ r, v @ r
    candidates = []
    det = uu * vv - uv * uv
    if det > 1e-14 * max(uu * vv, 1e-300):
        s, t = np.linalg.solve([[uu, -uv], [-uv, vv]], [-ur, vr])
        if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0:
            candidates.append((s, t))
    for s in (0.0, 1.0):  # t free on the edge, the convex 1-D minimum clamped
        candidates.append((s, min(max((vr + s * uv) / vv, 0.0), 1.0) if vv > 0 else 0.0))
    for t in (0.0, 1.0):
        candidates.append((min(max((t * uv - ur) / uu, 0.0), 1.0) if uu > 0 else 0.0, t))
    return min(float(np.linalg.norm(r + s * u - t * v)) for s, t in candidates)


def self_distances(origins: Array, k: int) -> Array:
    """Distances (m) of every pair of guarded links with no common point (an arm of k body
    points; the rail point's carriage link if ``origins`` has one), in :func:`link_pairs`
    order."""
    ends = guarded_links(k, origins.shape[0] > k + 1)
    i, j = link_pairs(k, origins.shape[0] > k + 1)
    return np.array(
        [
            segment_distance(
                origins[ends[a, 0]], origins[ends[a, 1]], origins[ends[b, 0]], origins[ends[b, 1]]
            )
            for a, b in zip(i, j, strict=True)
        ]
    )


# -- the verification -------------------------------------------------------------------------


@dataclass(frozen=True)
class Verified:
    """Exact values of one limit at a state: ``values`` (V,), their ``safe`` value and
    ``tolerance``, the limit's ``quantity``."""

    values: Array
    safe: float
    tolerance: float
    quantity: str


def verified_values(limits: tuple, robot: Robot, q: Array, radius: float) -> list[Verified]:  # type: ignore[type-arg]
    """The exact values each verified limit of ``limits`` keeps at ``q``, from the oracles."""
    f = frames(robot, q, radius)
    period = 2.0 * math.pi * radius
    out = []
    for limit in limits:
        kind = type(limit)
        if kind is JointPositionLimit:
            values = np.concatenate([limit.q_max - q, q - limit.q_min])
            out.append(Verified(values, 0.0, limit.tolerance, "joint position"))
        elif kind is ObstacleDamper and any(math.isfinite(o.height) for o in limit.obstacles):
            from tests.safety import real_link_distances  # (it imports this module)

            # the solids' true clearances: the real links sampled in 3-D (dvqp's are within
            # PRECISION below them where they matter, not the footprints' rule rebuilt)
            points = point_distances(limit.obstacles, f.guarded[:, :3], period)
            links = real_link_distances(limit.obstacles, f, radius)
            values = np.concatenate([points.ravel(), links.ravel()])
            out.append(Verified(values, limit.margin, limit.tolerance, limit.quantity))
        elif kind is ObstacleDamper and len(limit.obstacles):
            points = point_distances(limit.obstacles, f.guarded[:, :2], period)
            dampers = [d for d in limits if type(d) is ObstacleDamper]
            refine = np.array(
                [
                    max(d.margin for d in dampers if any(o is x for x in d.obstacles))
                    for o in limit.obstacles
                ]
            )
            union = list({id(x): x for d in dampers for x in d.obstacles}.values())
            links = real_clearances(
                limit.obstacles, f, radius, refine, closest_parts(union, f, radius)
            )[0]
            values = np.concatenate([points.ravel(), links.ravel()])
            out.append(Verified(values, limit.margin, limit.tolerance, limit.quantity))
        elif kind in (SurfaceHeight, ProbeHeight):
            body = kind is SurfaceHeight
            links = [*range(f.k - 1), *([f.k] if f.rail else [])] if body else [f.k - 1]
            ends = guarded_links(f.k, f.rail)
            lows = [
                chord_low(f.origins[ends[i, 0]], f.origins[ends[i, 1]], radius)[0] for i in links
            ]
            heights = f.guarded[: f.k, 2] if body else f.guarded[f.k : f.k + 1, 2]
            out.append(
                Verified(
                    np.concatenate([heights, lows]), limit.safe, limit.tolerance, limit.quantity
                )
            )
        elif kind is TiltLimit and limit.min_tilt > 0.0:
            angle = tilt(f)
            out.append(
                Verified(
                    np.array([min(angle, math.pi - angle)]),
                    limit.min_tilt,
                    limit.tolerance,
                    limit.quantity,
                )
            )
        elif kind is SelfCollision:
            out.append(
                Verified(
                    self_distances(f.origins, f.k), limit.margin, limit.tolerance, limit.quantity
                )
            )
    return out


def worst_excess(start: list[Verified], now: list[Verified]) -> tuple[float, float, str]:
    """``(value, ratio, quantity)`` of the worst excess at a state (``now``) of a run that
    started at ``start``: ``value = min(safe, value at the start) − value``, the worst by
    ``value / tolerance``."""
    best = (-math.inf, -math.inf, "")
    for s, v in zip(start, now, strict=True):
        over = np.minimum(s.safe, s.values) - v.values
        i = int(np.argmax(over / v.tolerance))
        if over[i] / v.tolerance > best[1]:
            best = (float(over[i]), float(over[i] / v.tolerance), v.quantity)
    return best


# -- optimality -------------------------------------------------------------------------------


def active_rows(
    G: Array | None, h: Array | None, lb: Array, ub: Array, x: Array, tol: float = 1e-7
) -> Array:
    """The outward normals (rows) of the inequalities ``x`` holds within ``tol`` of equality:
    rows of ``G``, ``−e_i`` at a lower bound, ``e_i`` at an upper bound."""
    n = x.shape[0]
    rows = [] if G is None else [G[i] for i in np.flatnonzero(h - G @ x < tol)]  # type: ignore[operator]
    rows += [-np.eye(n)[i] for i in np.flatnonzero(x - lb < tol)]
    rows += [np.eye(n)[i] for i in np.flatnonzero(ub - x < tol)]
    return np.array(rows).reshape(-1, n)


def nnls(M: Array, d: Array, tol: float = 1e-13) -> tuple[Array, float]:
    """``argmin ‖M z − d‖`` over ``z ≥ 0`` and the residual (Lawson and Hanson's active set)."""
    k = M.shape[1]
    z, passive = np.zeros(k), np.zeros(k, dtype=bool)
    for _ in range(3 * k + 10):
        w = M.T @ (d - M @ z)
        if passive.all() or w[~passive].max() <= tol * (1.0 + np.abs(d).max()):
            break
        passive[np.argmax(np.where(passive, -np.inf, w))] = True
        while True:
            trial = np.zeros(k)
            trial[passive] = np.linalg.lstsq(M[:, passive], d, rcond=None)[0]
            if (trial[passive] > 0.0).all():
                z = trial
                break
            shrink = passive & (trial <= 0.0)
            alpha = np.min(z[shrink] / (z[shrink] - trial[shrink]))
            z = z + alpha * (trial - z)
            passive &= z > 0.0
    return z, float(np.linalg.norm(M @ z - d))


def kkt_residual(
    P: Array,
    q: Array,
    A: Array,
    b: Array,
    G: Array | None,
    h: Array | None,
    lb: Array,
    ub: Array,
    x: Array,
    relaxed: float | None = None,
) -> float:
    """How far ``x`` is from optimal for ``min ½ xᵀPx + qᵀx`` s.t. ``A x = b`` (or, if
    ``relaxed`` = ρ, with ``+ ½ ρ ‖A x − b‖²`` in the cost instead), ``G x ≤ h``,
    ``lb ≤ x ≤ ub``: the smallest ``‖∇f + Aᵀν + Σ λ_i a_i‖`` over free ν and ``λ ≥ 0`` on
    the active inequalities ``a_i`` (ν projected out, λ by non-negative least squares),
    relative to ``1 + ‖∇f‖``. A convex QP's feasible point with residual 0 is its minimiser."""
    grad = P @ x + q
    rows = active_rows(G, h, lb, ub, x).T  # (n, a)
    if relaxed is None:  # the part of a vector that no Aᵀν cancels
        project = lambda v: v - A.T @ np.linalg.lstsq(A.T, v, rcond=None)[0]  # noqa: E731
        target, columns = (
            project(grad),
            np.column_stack([project(c) for c in rows.T] or [np.zeros(x.shape[0])]),
        )
    else:
        grad = grad + relaxed * A.T @ (A @ x - b)
        target, columns = grad, rows if rows.shape[1] else np.zeros((x.shape[0], 1))
    _, residual = nnls(columns, -target)
    return residual / (1.0 + float(np.linalg.norm(grad)))
