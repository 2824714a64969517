"""DAQP's own C functions called from compiled code: a solve in one compiled call.

:func:`stacked_solve` copies a problem into the buffers of a DAQP workspace set up through
DAQP's C API (:class:`solvers.daqp_abi.Workspace`), updates DAQP's LDP as ``daqp.Model.update``
does, solves, and checks the answer's residuals on the data the solve used: what
``Model.update``, ``Model.solve`` and the adapter's two compiled calls did with four Python
round trips, an info dict and two array copies between them. :func:`solve_stacked` is that
call from Python; :func:`solve_dropped` the first attempt of a row-dropping solve, for compiled
callers (dvqp's step) over one packed struct (:class:`AttemptCall`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from llvmlite import ir
from numba import types
from numba.core.extending import intrinsic

from ._fast import stack_into
from ._kkt import HAS_LB, HAS_UB, MISFITTING, _readonly, stacked_values
from .clock import now
from .daqp_abi import (
    _ACTIVE_AT,
    _EQ_AT,
    _LAM_STAR_AT,
    _QP_SENSE,
    _RES_FLAG,
    _RES_LAM,
    _RES_WORDS,
    _RES_X,
    _SCALING_AT,
    _SENSE_AT,
    _WS_AT,
    H_CLOCK,
    H_PROBLEM,
    H_RESULT,
    H_SENSE,
    H_SOLVE,
    H_UPDATE,
    H_WORK,
)
from .farkas import refuted
from .jit import compiled_on_first_call, njit
from .residuals import accepts
from .rows import compact, resized

UPDATE_RINV, UPDATE_M, UPDATE_V, UPDATE_SENSE = 1, 2, 4, 16
"""``DAQP_UPDATE_*`` bits of ``daqp_update_ldp``'s mask (DAQP's ``constants.h``)."""

WARM, RESTART, REFACTOR, AS_SET_UP = 0, 1, 2, 4
"""Bits of :func:`solve_stacked`'s ``mode``: none, keep the working set of the last solve (the
constraints' states DAQP holds); ``RESTART``, start afresh from the set-up's ``sense`` with
``H`` factored again; ``REFACTOR``, factor ``H`` again (it changed in ``data``, written by the
caller); ``AS_SET_UP``, solve the data as the set-up left it (no copy, no update)."""
MISFITTED, UPDATE_FAILED, SOLVED, ACCEPTED = 0.0, 1.0, 2.0, 3.0
"""Stages of :func:`stacked_solve`'s values (and :func:`solve_dropped`'s: ``ACCEPTED``)."""
INFEASIBLE = -1
"""DAQP's exit flag for a problem it found infeasible (``DAQP_EXIT_INFEASIBLE``)."""
CERTIFIED = -101
"""The exit flag of a cold restart refused without a solve: the multipliers in ``lam`` prove
that no answer can pass the check (:func:`solvers.farkas.refuted`). DAQP's own flags are -7
to 2."""
_NO_ANSWER = (0.0,) + (math.nan,) * 7
"""The check's values of a certified refusal: no ``x`` (code 0: not finite)."""


@intrinsic
def _read_word(typingctx, address):  # type: ignore[no-untyped-def]
    """The int64 at ``address``."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        pointer = builder.inttoptr(args[0], ir.IntType(64).as_pointer())
        return builder.load(pointer)

    return types.int64(types.int64), codegen


@intrinsic
def _read_int(typingctx, address):  # type: ignore[no-untyped-def]
    """The C ``int`` (int32) at ``address``, as an int64."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        pointer = builder.inttoptr(args[0], ir.IntType(32).as_pointer())
        return builder.sext(builder.load(pointer), ir.IntType(64))

    return types.int64(types.int64), codegen


@intrinsic
def _read_float(typingctx, address):  # type: ignore[no-untyped-def]
    """The C ``double`` at ``address``."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        pointer = builder.inttoptr(args[0], ir.DoubleType().as_pointer())
        return builder.load(pointer)

    return types.float64(types.int64), codegen


@njit(inline="always")
def _write_direction(work: int, n: int, ray: np.ndarray) -> None:
    """DAQP's infeasibility direction written into ``ray`` (ms + p + m,), in the order and
    signs of its multipliers, after a solve DAQP found infeasible (exit flag
    :data:`INFEASIBLE`).

    DAQP finds a problem infeasible mostly when the dual direction it would step along
    (``lam_star`` over the working set ``WS``, the singular direction its last added
    constraint made) meets no blocking constraint: a nonnegative (signed: a lower side's
    negative) combination of the working set's rows that vanishes while their bounds
    combine to a contradiction, the certificate of Farkas' lemma. DAQP writes no multipliers
    then; this reads the direction from its workspace, undoing the rows' normalisation as
    DAQP does for an answer's multipliers (``ldp2qp_solution``). DAQP's other infeasible
    exits (an inconsistent dual, its objective bound) leave multipliers that are no ray, and
    a workspace whose equalities DAQP eliminated (``eq_reduction``: ``work->eq`` set)
    describes the reduced problem: ``ray`` is left as it was then. Nothing here trusts the
    direction: a restart tests it on the data (:func:`solvers.farkas.refuted`). ``ray`` is
    left zero if the working set does not fit it (DAQP holds at most ``n + 1`` rows, each of
    ``ray``'s)."""
    if _read_word(work + _EQ_AT) != 0:
        return
    rows = ray.shape[0]
    active = _read_int(work + _ACTIVE_AT)
    for i in range(rows):
        ray[i] = 0.0
    if active < 0 or active > rows or active > n + 1:
        return
    ws, star = _read_word(work + _WS_AT), _read_word(work + _LAM_STAR_AT)
    scaling = _read_word(work + _SCALING_AT)
    for i in range(active):
        row = _read_int(ws + 4 * i)
        if row < 0 or row >= rows:
            for j in range(rows):
                ray[j] = 0.0
            return
        value = _read_float(star + 8 * i)
        if scaling != 0:
            value *= _read_float(scaling + 8 * row)
        ray[row] = value


@intrinsic
def _update_ldp(typingctx, function, mask, work, problem):  # type: ignore[no-untyped-def]
    """``daqp_update_ldp(mask, work, problem)`` at the address ``function``."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        i8p = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), i8p, i8p])
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        flag = builder.call(
            callee,
            [
                builder.trunc(args[1], ir.IntType(32)),
                builder.inttoptr(args[2], i8p),
                builder.inttoptr(args[3], i8p),
            ],
        )
        return builder.sext(flag, ir.IntType(64))

    return types.int64(types.int64, types.int64, types.int64, types.int64), codegen


@intrinsic
def _solve(typingctx, function, result, work):  # type: ignore[no-untyped-def]
    """``daqp_solve(result, work)`` at the address ``function``."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        i8p = ir.IntType(8).as_pointer()
        fnty = ir.FunctionType(ir.VoidType(), [i8p, i8p])
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(callee, [builder.inttoptr(args[1], i8p), builder.inttoptr(args[2], i8p)])
        return context.get_dummy_value()

    return types.none(types.int64, types.int64, types.int64), codegen


_VEC_IN = types.Array(types.float64, 1, "C", readonly=True)
_MAT_IN = types.Array(types.float64, 2, "C", readonly=True)
_VEC_OUT = types.Array(types.float64, 1, "C")
_WORDS = types.Array(types.int64, 1, "C")
_VALUES = types.UniTuple(types.float64, 12)


@njit(separate=True)
def stacked_solve(
    P: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    data: np.ndarray,
    handles: np.ndarray,
    words: np.ndarray,
    n: int,
    p: int,
    m: int,
    ms: int,
    flags: int,
    mode: int,
    refute: float,
    x: np.ndarray,
    lam: np.ndarray,
    ray: np.ndarray,
) -> tuple[float, ...]:
    """Copy a problem into the set-up's ``data`` (:func:`solvers._fast.stack_into`), update
    DAQP's LDP as ``daqp.Model.update(H, f, A)`` does, solve into ``x`` (n,) and ``lam``
    (ms + p + m,), and check the answer on ``data``.

    ``handles`` and ``words`` are a :class:`~solvers.daqp_abi.Workspace`'s ``handles`` and
    the words behind its problem and result; ``mode`` holds the bits :data:`RESTART`,
    :data:`REFACTOR` and :data:`AS_SET_UP` (none: warm, from the working set of the last
    solve). With ``refute`` ≥ 0 (the check's tolerance; negative: never), a solve DAQP
    finds infeasible whose answer the check refuses leaves DAQP's infeasibility direction in
    ``ray`` (ms + p + m,; DAQP itself writes no multipliers then: :func:`_write_direction`),
    and a cold restart first tries the multipliers ``lam`` holds (those
    :func:`hold_multipliers` put there, or the last answer's), then that direction, as a
    certificate that the new data admits no answer within that tolerance
    (:func:`solvers.farkas.refuted`): if either
    proves it, nothing is solved, ``x`` is NaN, ``ray`` and ``lam`` are kept (the next
    restart tries them again) and the flag is :data:`CERTIFIED`. ``lam`` itself is only
    ever DAQP's (or held there by a caller): an answer is judged with the same multipliers
    with or without proofs.

    Returns
    -------
    tuple of 12 floats
        ``(stage, flag, iterations, seconds, *values)``: stage :data:`MISFITTED` a size
        misfits (nothing done), :data:`UPDATE_FAILED` (``flag`` its exit flag), or
        :data:`SOLVED` (``flag`` DAQP's exit flag, or :data:`CERTIFIED` with 0 iterations and
        code 0 values); ``seconds`` inside DAQP's update and solve; ``values`` those of
        :func:`solvers._kkt.stacked_values` (NaN unless solved).
    """
    nan = math.nan
    rows = ms + p + m
    if x.shape[0] != n or lam.shape[0] != rows or ray.shape[0] != rows:
        return (MISFITTED, nan, nan, 0.0, *MISFITTING)
    changed = 0 if mode & AS_SET_UP else stack_into(P, q, A, b, G, h, lb, ub, data, n, p, m, ms)
    if changed < 0:
        return (MISFITTED, nan, nan, 0.0, *MISFITTING)
    restart = (mode & RESTART) != 0 and (mode & AS_SET_UP) == 0
    box = (flags & HAS_LB) != 0, (flags & HAS_UB) != 0
    if restart and refute >= 0.0 and _either_proves(data, ray, lam, n, p, m, ms, box, refute):
        return certified(x)
    work, problem, result = handles[H_WORK], handles[H_PROBLEM], handles[H_RESULT]
    started = now(handles[H_CLOCK])
    if not mode & AS_SET_UP:
        mask = UPDATE_M | UPDATE_V | UPDATE_SENSE
        if changed or mode & (RESTART | REFACTOR):
            mask |= UPDATE_RINV
        restart = mode & RESTART
        words[_QP_SENSE] = handles[H_SENSE] if restart else _read_word(work + _SENSE_AT)
        flag = _update_ldp(handles[H_UPDATE], mask, work, problem)
        if flag < 0:
            spent = now(handles[H_CLOCK]) - started
            return (UPDATE_FAILED, float(flag), nan, spent, *MISFITTING)
    base = words.shape[0] - _RES_WORDS  # the DAQPResult, after the DAQPProblem
    for i in range(_RES_WORDS):
        words[base + i] = 0
    words[base + _RES_X] = x.ctypes.data
    words[base + _RES_LAM] = lam.ctypes.data if rows else 0
    _solve(handles[H_SOLVE], result, work)
    spent = now(handles[H_CLOCK]) - started
    both = words[base + _RES_FLAG // 2]  # exitflag and iter, one word (little-endian)
    exitflag, iterations = np.int32(both & 0xFFFFFFFF), both >> 32
    values = stacked_values(data, x, lam, n, p, m, ms, flags)
    if exitflag == INFEASIBLE and refute >= 0.0 and rows > 0 and not accepts(values, refute):
        _write_direction(work, n, ray)  # for the restart to try first
    return (SOLVED, float(exitflag), float(iterations), spent, *values)


@njit(inline="always")
def _either_proves(data, ray, lam, n, p, m, ms, box, refute) -> bool:  # type: ignore[no-untyped-def]
    """Whether the multipliers ``lam`` holds or DAQP's last infeasibility direction (``ray``)
    prove the problem in ``data`` infeasible at ``refute`` (:func:`solvers.farkas.refuted`):
    ``lam`` first, where a caller holds the multipliers that proved the last refusals (a
    streak's: one test a step), then the direction (a warm refusal's, fresh)."""
    return refuted(data, lam, n, p, m, ms, box[0], box[1], refute) or refuted(
        data, ray, n, p, m, ms, box[0], box[1], refute
    )


@compiled_on_first_call(
    _VALUES(
        *(_MAT_IN, _VEC_IN) * 3,
        _VEC_IN,
        _VEC_IN,
        _VEC_OUT,
        _WORDS,
        _WORDS,
        *(types.int64,) * 6,
        types.float64,
        _VEC_OUT,
        _VEC_OUT,
        _VEC_OUT,
    )
)
def solve_stacked(
    P: np.ndarray,
    q: np.ndarray,
    A: np.ndarray,
    b: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    lb: np.ndarray,
    ub: np.ndarray,
    data: np.ndarray,
    handles: np.ndarray,
    words: np.ndarray,
    n: int,
    p: int,
    m: int,
    ms: int,
    flags: int,
    mode: int,
    refute: float,
    x: np.ndarray,
    lam: np.ndarray,
    ray: np.ndarray,
) -> tuple[float, ...]:
    """:func:`stacked_solve`, compiled for its one signature, called from Python."""
    return stacked_solve(
        P,
        q,
        A,
        b,
        G,
        h,
        lb,
        ub,
        data,
        handles,
        words,
        n,
        p,
        m,
        ms,
        flags,
        mode,
        refute,
        x,
        lam,
        ray,
    )


@dataclass(frozen=True)
class AttemptCall:
    """What a solve's first attempt in compiled code needs (:func:`solve_dropped`): the bound
    problem's arrays (``P`` .. ``ub``, absent blocks as empty arrays), the set-up's ``data``,
    ``handles`` and ``words``, its sizes and ``flags`` (:func:`stacked_solve`'s), the
    attempt's ``mode`` ((1,): :data:`WARM` or :data:`RESTART`), the check's ``tolerance``
    (:func:`solvers.residuals.accepts`), ``refute`` (:func:`stacked_solve`'s: the tolerance at
    which a restart tries DAQP's direction ``ray`` and the multipliers in ``lam`` as a
    certificate; negative: never), and buffers for the answer ``x`` (n,) and ``lam``
    (ms + p + m,) and for DAQP's infeasibility direction ``ray`` (ms + p + m,). Valid
    while its backend keeps the set-up and the problem it was made for
    (:meth:`solvers.daqp_.DaqpBackend.compiled_attempt`)."""

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    G: np.ndarray
    h: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    data: np.ndarray
    handles: np.ndarray
    words: np.ndarray
    n: int
    p: int
    m: int
    ms: int
    flags: int
    mode: np.ndarray
    tolerance: float
    refute: float
    x: np.ndarray
    lam: np.ndarray
    ray: np.ndarray


@njit(separate=True, python=True)  # dvqp's step calls it, and its resolver from Python
def solve_dropped(w):  # type: ignore[no-untyped-def]
    """A :class:`~solvers.rows.RowDropping` solve's first attempt over DAQP's C functions, in
    compiled code: ``w`` is its :class:`~solvers.rows.AttemptRows` packed into one struct (its
    ``call`` a packed :class:`AttemptCall`). Drops the rows (:func:`~solvers.rows.compact`)
    and, unless the copy's capacity would change, makes the attempt (:func:`stacked_solve`, in
    the call's ``mode``: warm, or the cold restart after a refusal).

    Returns
    -------
    tuple of 12 floats
        :func:`stacked_solve`'s values (the backend's ``adopt_attempt`` finishes an attempt
        from them), their stage :data:`ACCEPTED` when the answer passes the residual check
        (:func:`solvers.residuals.accepts`, at the call's ``tolerance``), or stage −1 when the
        capacity would change (nothing solved: the backend's ``solve`` takes it from there, the
        rows dropped again to the same slots).
    """
    used = compact(w.G, w.h, w.slot_of, w.row_of, w.Gc, w.hc)
    if resized(used, w.capacity, w.hc.shape[0]) != w.capacity:
        return (-1.0, *MISFITTING, 0.0, 0.0, 0.0)
    return attempt(w.call)


@njit(inline="always")
def attempt(c):  # type: ignore[no-untyped-def]
    """The attempt of the packed :class:`AttemptCall` ``c`` on its set-up's rows as they
    are, in its ``mode`` (:func:`stacked_solve`), its answer checked: stage
    :data:`ACCEPTED` when it passes (:func:`solvers.residuals.accepts`). A caller that made
    a warm attempt and saw it refused makes the backend's cold restart so, in mode
    :data:`RESTART` (what the backend's ``after_warm`` makes)."""
    out = stacked_solve(  # read-only data: the types solve_stacked declares, one compile
        _readonly(c.P),
        _readonly(c.q),
        _readonly(c.A),
        _readonly(c.b),
        _readonly(c.G),
        _readonly(c.h),
        _readonly(c.lb),
        _readonly(c.ub),
        c.data,
        c.handles,
        c.words,
        c.n,
        c.p,
        c.m,
        c.ms,
        c.flags,
        c.mode[0],
        c.refute,
        c.x,
        c.lam,
        c.ray,
    )
    if out[0] == SOLVED and accepts(out[4:], c.tolerance):
        return (ACCEPTED, *out[1:])
    return out


@njit(inline="always")
def certified(x: np.ndarray) -> tuple[float, ...]:
    """The values of a refusal certified without a solve (:data:`CERTIFIED`: 0 iterations
    and seconds, code 0 values), its ``x`` (n,) written NaN."""
    for i in range(x.shape[0]):
        x[i] = math.nan
    return (SOLVED, float(CERTIFIED), 0.0, 0.0, *_NO_ANSWER)


@njit(inline="always")
def proves(c) -> bool:  # type: ignore[no-untyped-def]
    """Whether the multipliers in the packed :class:`AttemptCall` ``c``'s ``lam``, or DAQP's
    direction in its ``ray``, prove the problem its ``data`` holds (as an attempt copied
    it) infeasible at its ``refute`` tolerance (:func:`solvers.farkas.refuted`; never if
    negative): what its next restart finds before it solves."""
    box = (c.flags & HAS_LB) != 0, (c.flags & HAS_UB) != 0
    return c.refute >= 0.0 and _either_proves(
        c.data, c.ray, c.lam, c.n, c.p, c.m, c.ms, box, c.refute
    )


@njit(separate=True)  # compiled callers only (dvqp's step loop)
def hold_multipliers(source, target) -> None:  # type: ignore[no-untyped-def]
    """The multipliers of ``source``'s last answer held in ``target``'s ``lam``, where
    ``target``'s next cold restart tries them as a certificate that its problem admits no
    answer (:func:`stacked_solve`, ``refute``): ``source`` and ``target`` are packed
    :class:`~solvers.rows.AttemptRows` (their ``call`` an :class:`AttemptCall`) of two problems
    whose equality rows and inequality rows are the same, row for row (e.g. a task relaxed with
    slack columns, and the task strict). Each inequality row's multiplier moves from its slot
    in ``source``'s copy to its slot in ``target``'s (0 where ``source`` has none), the
    equality rows' as they are; the bounds' are left (the certificate does not read them).
    Nothing is held if the equality rows differ in number.

    (A restart tries DAQP's direction of the last refusal it found, in ``ray``, after
    these.)"""
    s, t = source.call, target.call
    if s.m != t.m:
        return
    for slot in range(t.p):
        row = target.row_of[slot]
        held = 0.0
        if row >= 0:
            at = source.slot_of[row]
            if 0 <= at < s.p:
                held = s.lam[s.ms + at]
        t.lam[t.ms + slot] = held
    for i in range(t.m):
        t.lam[t.ms + t.p + i] = s.lam[s.ms + s.p + i]
