"""The compiled step, stage by stage: one readable pipeline over dvqp's part kinds.

:func:`evaluate` measures a configuration (kinematics, obstacles, link pairs), assesses it (the
objective, the dampers' distances) and concludes (the exact verification, the diagnostics, the
trajectory's sample); :func:`prepare` writes a step's QP (the tasks' rows, the cost, the
bounds, the damper rows) and closes it, :func:`prepare_baseline` the baseline's step. Each
stage calls the kernels of the parts' own modules on the arrays of one packed
:class:`~dvqp.step.arrays.Pipeline`. A run with parts of your own calls the stages one at a
time (``first``, ``last``) and runs its parts in between (:mod:`dvqp.step.hooks`).
"""

from __future__ import annotations

import math

from dvqp.geometry.link_pieces import straight_solids
from dvqp.geometry.measure import measure_chain, penalties
from dvqp.geometry.real_links import real_links
from dvqp.kinematics.model import kinematics
from dvqp.limits.acceleration import acceleration_bounds
from dvqp.limits.damper import damper_rows, damper_values
from dvqp.limits.excess import worst_excess
from dvqp.limits.height import chord_heights, height_distances, lowest_chords
from dvqp.limits.joints import joint_room, position_bounds, velocity_bounds
from dvqp.limits.obstacle_damper import obstacle_distances
from dvqp.limits.self_collision import pair_distances, self_distances
from dvqp.limits.tilt import tilt_angle, tilt_distance
from dvqp.objective.obstacle_links import obstacle_links
from dvqp.objective.obstacle_points import obstacle_points
from dvqp.objective.orbital_level import orbital_level
from dvqp.resolution.pinv import NOT_DEFINITE, pinv_step
from dvqp.tasks.point import point_rows
from dvqp.tasks.posture import posture_rows
from dvqp.tasks.tool_dv import tool_rows
from solvers.clock import now
from solvers.daqp_c import ACCEPTED, H_CLOCK, WARM, solve_dropped
from solvers.jit import njit

MEASURE, LINKS, OBJECTIVE, DAMPERS, CONCLUDE = 0, 1, 2, 3, 4
"""Stages of :func:`evaluate`: the kinematics and the obstacles' distances, the real links,
the objective, the dampers' distances, the exact verification (and the sample)."""
ASSESS = LINKS
"""The first stage after a run's measuring parts of your own (:mod:`dvqp.step.hooks`); they
assess after :data:`DAMPERS`."""
ROWS, CLOSE = 0, 1
"""Stages of :func:`prepare`."""
NOT_ATTEMPTED = (-1.0,) + (math.nan,) * 11
""":func:`resolve_move`'s attempt values when it made none."""
SINGULAR_TASK, INDEFINITE_METRIC, BAD_COMMAND = -2, -3, -4
"""Statuses of :func:`prepare`: the baseline's Gram matrix or metric is singular; the command
is not finite."""
MOVED, ATTEMPTED = -5, -6
"""Statuses of :func:`resolve_move`: the step resolved and made; the strict problem's first
attempt made, not taken as it is."""


@njit(separate=True)
def evaluate(s, integrate, first, last) -> int:  # type: ignore[no-untyped-def]
    """Evaluate the state at ``s.state.q`` (first ``q += dt·x`` if ``integrate``), stages
    ``first`` to ``last``; returns −1, or the index of a singular guarded frame."""
    if first <= MEASURE <= last:
        if integrate:
            _integrate(s)
        singular = kinematics(s.model, s.radius, s.state)
        if singular != -1:
            return singular  # type: ignore[no-any-return]
        measure_chain(s.shapes, s.state.guarded, s.near)
        pair_distances(s.state.origins, s.pairs)
    if first <= LINKS <= last:
        real_links(s.shapes, s.state.guarded, s.state.origins, s.radius, s.model.tool, s.near)
        straight_solids(s.shapes, s.state.guarded, s.near)  # obstacles with a height only
        penalties(s.shapes, s.near)  # the paper's w: of the straight DV links
    if first <= OBJECTIVE <= last:
        _objective(s)
    if first <= DAMPERS <= last:
        _distances(s)
    if first <= CONCLUDE <= last:
        _conclude(s)
    return -1


@njit(inline="always")
def _integrate(s) -> None:  # type: ignore[no-untyped-def]
    """``s.motion = [‖A x − b‖∞, max |dt x|]``, each level's ``‖A x − b‖∞`` and ``q += dt x``."""
    A, b, x, q, dt = s.qp.A, s.qp.b, s.x, s.state.q, s.dt[0]
    levels, level_error = s.tasks.levels, s.tasks.level_error
    error = 0.0
    for level in range(level_error.shape[0]):
        worst = 0.0
        for r in range(levels[level], levels[level + 1]):
            v = -b[r]
            for c in range(A.shape[1]):
                v += A[r, c] * x[c]
            worst = max(worst, abs(v))
        level_error[level] = worst
        error = max(error, worst)
    largest = 0.0
    for i in range(q.shape[0]):
        moved = q[i] + dt * x[i]
        largest = max(largest, abs(moved - q[i]))
        q[i] = moved
    s.motion[0], s.motion[1] = error, largest


@njit(inline="always")
def _objective(s) -> None:  # type: ignore[no-untyped-def]
    """``w`` and ``∂w/∂Q`` of dvqp's terms (a user's are added after)."""
    o, st, near = s.objective, s.state, s.near
    o.value[0] = 0.0
    for c in range(o.gradient.shape[0]):
        o.gradient[c] = 0.0
    for t in range(o.levels.shape[0]):
        orbital_level(
            st.guarded, st.guarded_jacobians, o.levels[t], o.k_height[t], o.value, o.gradient
        )
    obstacle_points(
        near.point_penalty,
        near.point_penalty_gradient,
        near.skipped,
        o.point_coef,
        st.guarded_jacobians,
        o.scratch,
        o.value,
        o.gradient,
    )
    obstacle_links(
        near.link_penalty,
        near.link_penalty_gradient,
        near.skipped,
        near.link_penalty_at,
        o.link_coef,
        st.guarded_jacobians,
        o.scratch,
        o.value,
        o.gradient,
    )


@njit(inline="always")
def _distances(s) -> None:  # type: ignore[no-untyped-def]
    """The distances of dvqp's dampers, each into its rows."""
    m, st, d = s.measures, s.state, s.dampers
    out = (d.distance, d.gradient, d.usable)
    for o in range(m.obstacle_start.shape[0]):
        members = m.obstacle_members[m.obstacle_offsets[o] : m.obstacle_offsets[o + 1]]
        obstacle_distances(
            s.near,
            st.guarded_jacobians,
            st.origins,
            st.frame_jacobians,
            s.radius,
            s.params.reach,
            members,
            m.obstacle_start[o],
            *out,
        )
    for i in range(m.heights.shape[0]):
        start, first, count = m.heights[i, 0], m.heights[i, 1], m.heights[i, 2]
        height_distances(st.guarded, st.guarded_jacobians, first, count, start, *out)
    chord_heights(st.guarded, st.origins, st.frame_jacobians, s.near.ends, s.radius, m.chords, *out)
    for i in range(m.tilts.shape[0]):
        tilt_distance(st.origins, st.axes, st.frame_jacobians, s.model.tool, m.tilts[i], *out)
    for i in range(m.selves.shape[0]):
        self_distances(s.pairs, st.frame_jacobians, m.selves[i], *out)


@njit(inline="always")
def _conclude(s) -> None:  # type: ignore[no-untyped-def]
    """The verified values and their worst excess, the diagnostics, the sample."""
    c, st = s.checks, s.state
    if s.joint_values >= 0:
        joint_room(st.q, s.bounds.q_min, s.bounds.q_max, c.values, s.joint_values)
    if s.damper_values >= 0:
        damper_values(s.params.angle, s.dampers.distance, c.values, s.damper_values)
    worst_excess(c.values, c.floor, c.tolerance, c.excess)
    _diagnostics(s)
    if s.record.index[0] >= 0:
        _sample(s)


@njit(inline="always")
def _diagnostics(s) -> None:  # type: ignore[no-untyped-def]
    """``[tilt, self distance, min clearance, probe clearance, closest part, lowest link
    chord, lowest holder point]`` (rad, m, m, m, index ``r (m + L) + i`` of recorded obstacle
    r's point i, or ``+ m`` of its link i, m, m)."""
    st, near, out, k = s.state, s.near, s.diagnostics, s.model.tool
    out[0] = tilt_angle(st.origins, st.axes, k)
    out[5], _, out[6] = lowest_chords(st.guarded, st.origins, near.ends, k, s.radius, s.base_link)
    out[1] = math.inf
    for p in range(s.pairs.distance.shape[0]):
        out[1] = min(out[1], s.pairs.distance[p])
    m, parts = near.point_distance.shape[1], near.point_distance.shape[1] + near.ends.shape[0]
    out[2], out[3], out[4] = math.inf, math.inf, -1.0
    for r in range(s.recorded.shape[0]):
        j = s.recorded[r]
        if near.skipped[j]:  # its rows are above the closest part's (real_links)
            continue
        for i in range(parts):
            d = near.point_distance[j, i] if i < m else near.real_distance[j, i - m]
            if d < out[2]:
                out[2], out[4] = d, r * parts + i
        out[3] = min(out[3], near.point_distance[j, k], near.real_distance[j, k - 1])


@njit(inline="always")
def _sample(s) -> None:  # type: ignore[no-untyped-def]
    """Row ``s.record.index[0]`` of the trajectory's samples, and each verified value's lowest
    over the samples."""
    r, st, at = s.record, s.state, s.record.index[0]
    for i in range(st.q.shape[0]):
        r.q[at, i] = st.q[i]
    for i in range(4):
        r.tool[at, i] = st.tool[i]
    for p in range(r.points.shape[1]):
        for i in range(3):
            r.points[at, p, i] = st.guarded[p, i]
    r.w[at] = s.objective.value[0]
    c = s.checks
    r.limit_excess[at], r.limits_kept[at] = max(c.excess[0], 0.0), c.excess[1] <= 1.0
    d = s.diagnostics
    r.tilt[at], r.self_distance[at], r.min_clearance[at], r.probe_clearance[at] = d[:4]
    r.link_height[at], r.holder_height[at] = d[5], d[6]
    if r.rail.shape[0] > 0:  # the rail point's [l, z, h], when recorded (the arm has one)
        for i in range(3):
            r.rail[at, i] = st.guarded[st.guarded.shape[0] - 1, i]
    if c.row[0] != at:  # a new sample: those before it are final
        c.row[0] = at
        for i in range(c.lowest.shape[0]):
            c.settled[i] = c.lowest[i]
    for i in range(c.lowest.shape[0]):  # NaN never lowers it (a NaN sample is not kept)
        c.lowest[i] = c.values[i] if c.values[i] < c.settled[i] else c.settled[i]


@njit(separate=True)
def prepare(s, first, last) -> int:  # type: ignore[no-untyped-def]
    """Write this step's QP (stage ``ROWS``: the tasks' rows, the cost, the bounds reset and
    every box intersected, the damper rows) and close it (``CLOSE``): returns −1, the first
    joint whose bounds cross, or :data:`BAD_COMMAND`."""
    qp, b, q, dt = s.qp, s.bounds, s.state.q, s.dt[0]
    if first <= ROWS <= last:
        if not _rows(s):
            return BAD_COMMAND
        for i in range(qp.lb.shape[0]):
            qp.lb[i], qp.ub[i] = -math.inf, math.inf
        position_bounds(q, b.q_min, b.q_max, dt, qp.lb, qp.ub)
        velocity_bounds(b.qd_max, qp.lb, qp.ub)
        if b.accelerate:
            acceleration_bounds(
                q, b.accel_q_min, b.accel_q_max, b.qdd_max, b.previous, dt, qp.lb, qp.ub
            )
        damper_rows(s.params, s.dampers, dt, qp.G, qp.h)
    if first <= CLOSE <= last:
        for i in range(qp.lb.shape[0]):
            if qp.lb[i] > qp.ub[i]:
                return i
    return -1


@njit(separate=True)
def prepare_baseline(s, first, last) -> int:  # type: ignore[no-untyped-def]
    """:func:`prepare` for the baseline (its own function: neither compiles the other's code),
    its step in ``s.pinv.x``: −1, :data:`SINGULAR_TASK`, :data:`INDEFINITE_METRIC` or
    :data:`BAD_COMMAND`."""
    qp, p = s.qp, s.pinv
    if first <= ROWS <= last and not _rows(s):
        return BAD_COMMAND
    if first <= CLOSE <= last:
        levels = s.tasks.levels
        status = pinv_step(
            qp.A, qp.b, levels, p.rows, qp.cost, p.weights, qp.P, p.dense, p.damping, p.info, p.x
        )
        if status != -1:
            return INDEFINITE_METRIC if status == NOT_DEFINITE else SINGULAR_TASK
    return -1


@njit(inline="always")
def _rows(s) -> bool:  # type: ignore[no-untyped-def]
    """The tasks' rows, the metric and the cost; False if the command is not finite."""
    qp, p = s.qp, s.pinv
    for i in range(4):
        if not math.isfinite(s.command[i]):
            return False
    t, st = s.tasks, s.state
    for i in range(t.tool.shape[0]):
        start, count = t.tool[i, 0], t.tool[i, 1]
        tool_rows(st.tool_jacobian, s.command, t.tool[i, 2 : 2 + count], qp.A, qp.b, start)
    period, g, dg = 2.0 * math.pi * s.radius, st.guarded, st.guarded_jacobians
    for i in range(t.point.shape[0]):
        start, count, point = t.point[i, 0], t.point[i, 1], t.point[i, 2]
        components, target, gain = t.point[i, 3 : 3 + count], t.point_target[i], t.point_gain[i]
        point_rows(g, dg, point, components, target, gain, period, qp.A, qp.b, start)
    for i in range(t.posture.shape[0]):
        posture_rows(st.q, t.posture_target[i], t.posture_gain[i], qp.A, qp.b, t.posture[i])
    if p.dense:
        for i in range(qp.P.shape[0]):
            for j in range(qp.P.shape[1]):
                qp.P[i, j] = p.weights[i] if i == j else 0.0
    gain = s.objective.gain
    for i in range(qp.cost.shape[0]):
        qp.cost[i] = -gain * s.objective.gradient[i]
    return True


@njit
def resolve_move(s, w):  # type: ignore[no-untyped-def]
    """A common QP step in one call: write the QP (:func:`prepare`), make the strict
    problem's first attempt (``w``: its backend's packed ``compiled_attempt``,
    :func:`solvers.daqp_c.solve_dropped`) and, if it was warm and its answer passed the
    check, take it as ``s.x`` and evaluate the state it reaches (:func:`evaluate`, as
    :meth:`~dvqp.step.Stepper.move`).

    Returns
    -------
    tuple of 15 floats
        ``(status, singular, moving, *attempt)``: status :data:`MOVED` (``singular``: −1 or
        the guarded frame on the pipe axis; ``moving``: the seconds the evaluation took, not
        the resolution's), :data:`ATTEMPTED` (the resolver finishes the solve from the
        attempt's values), or :func:`prepare`'s status when it is not −1 (nothing
        attempted); ``attempt`` the values of :func:`~solvers.daqp_c.solve_dropped`.
    """
    status = prepare(s, ROWS, CLOSE)
    if status != -1:
        return (float(status), 0.0, 0.0, *NOT_ATTEMPTED)
    out = solve_dropped(w)
    if out[0] != ACCEPTED or w.call.mode[0] != WARM:
        return (float(ATTEMPTED), 0.0, 0.0, *out)
    for i in range(s.x.shape[0]):
        s.x[i] = w.call.x[i]
    clock = w.call.handles[H_CLOCK]
    started = now(clock)
    singular = evaluate(s, True, MEASURE, CONCLUDE)
    return (float(MOVED), float(singular), now(clock) - started, *out)


@njit
def resolve_move_baseline(s, clock):  # type: ignore[no-untyped-def]
    """:func:`resolve_move` for the baseline: its step (:func:`prepare_baseline`) and, if it
    has one, the state it reaches evaluated. ``clock``: :func:`solvers.clock.address`.

    Returns
    -------
    tuple of 3 floats
        ``(status, singular, moving)``: :data:`MOVED` (as :func:`resolve_move`'s), or
        :func:`prepare_baseline`'s status when it is not −1.
    """
    status = prepare_baseline(s, ROWS, CLOSE)
    if status != -1:
        return (float(status), 0.0, 0.0)
    started = now(clock)
    singular = evaluate(s, True, MEASURE, CONCLUDE)
    return (float(MOVED), float(singular), now(clock) - started)
