"""DAQP's own C functions, called without ``daqp.Model``: a warm solve in one compiled call.

The ``daqp`` extension module exports DAQP's C API (``setup_daqp_main``, ``daqp_update_ldp``,
``daqp_solve``, ...). :class:`Workspace` allocates and sets up a DAQP workspace with them, as
``daqp.Model.setup`` does, and :func:`solve_stacked` is one compiled call that copies a problem
into the set-up's buffers, updates DAQP's LDP, solves, and checks the answer's residuals on the
data the solve used: what ``Model.update``, ``Model.solve`` and the adapter's two compiled
calls did with four Python round trips, an info dict and two array copies between them.

The structures below mirror DAQP's ``types.h`` and ``api.h`` of the versions in
:data:`KNOWN_VERSIONS`, and of no other: :func:`available` is False for any other version
(the adapter then keeps ``daqp.Model``). Two checks at the first use hold the mirror to the
library actually loaded: DAQP's default settings read through :class:`Settings` must equal
``daqp.Model().settings`` (the extension's own compiled layout), and after each set-up the
workspace must name the problem and its sizes where :class:`WorkspaceHead` says.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.metadata
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from llvmlite import ir
from numba import types
from numba.core.extending import intrinsic

from . import clock
from ._fast import stack_into
from ._kkt import MISFITTING, _readonly, stacked_values
from .clock import now
from .jit import compiled_on_first_call, njit
from .residuals import accepts
from .rows import compact, resized

KNOWN_VERSIONS = ("0.11.0",)
"""The ``daqp`` versions whose ``types.h`` the structures below mirror."""

UPDATE_RINV, UPDATE_M, UPDATE_V, UPDATE_SENSE = 1, 2, 4, 16
"""``DAQP_UPDATE_*`` bits of ``daqp_update_ldp``'s mask (DAQP's ``constants.h``)."""

WARM, RESTART, REFACTOR, AS_SET_UP = 0, 1, 2, 4
"""Bits of :func:`solve_stacked`'s ``mode``: none, keep the working set of the last solve (the
constraints' states DAQP holds); ``RESTART``, start afresh from the set-up's ``sense`` with
``H`` factored again; ``REFACTOR``, factor ``H`` again (it changed in ``data``, written by the
caller); ``AS_SET_UP``, solve the data as the set-up left it (no copy, no update)."""

_c_float_p = ctypes.POINTER(ctypes.c_double)
_c_int_p = ctypes.POINTER(ctypes.c_int)


class ProblemData(ctypes.Structure):
    """``DAQPProblem``: sizes and pointers to the data (``types.h``)."""

    _fields_ = [
        ("n", ctypes.c_int),
        ("m", ctypes.c_int),
        ("ms", ctypes.c_int),
        ("H", _c_float_p),
        ("f", _c_float_p),
        ("A", _c_float_p),
        ("bupper", _c_float_p),
        ("blower", _c_float_p),
        ("sense", _c_int_p),
        ("break_points", _c_int_p),
        ("nh", ctypes.c_int),
        ("problem_type", ctypes.c_int),
    ]


class Settings(ctypes.Structure):
    """``DAQPSettings``: the keys of ``daqp.Model().settings``, in DAQP's order."""

    _fields_ = [
        ("primal_tol", ctypes.c_double),
        ("dual_tol", ctypes.c_double),
        ("zero_tol", ctypes.c_double),
        ("pivot_tol", ctypes.c_double),
        ("progress_tol", ctypes.c_double),
        ("cycle_tol", ctypes.c_int),
        ("iter_limit", ctypes.c_int),
        ("fval_bound", ctypes.c_double),
        ("eps_prox", ctypes.c_double),
        ("eta_prox", ctypes.c_double),
        ("rho_soft", ctypes.c_double),
        ("rel_subopt", ctypes.c_double),
        ("abs_subopt", ctypes.c_double),
        ("sing_tol", ctypes.c_double),
        ("refactor_tol", ctypes.c_double),
        ("time_limit", ctypes.c_double),
        ("w_soft", ctypes.c_double),
        ("eq_reduction", ctypes.c_int),
        ("presolve", ctypes.c_int),
    ]


class Result(ctypes.Structure):
    """``DAQPResult`` (``api.h``)."""

    _fields_ = [
        ("x", _c_float_p),
        ("lam", _c_float_p),
        ("fval", ctypes.c_double),
        ("soft_slack", ctypes.c_double),
        ("exitflag", ctypes.c_int),
        ("iter", ctypes.c_int),
        ("nodes", ctypes.c_int),
        ("solve_time", ctypes.c_double),
        ("setup_time", ctypes.c_double),
    ]


_POINTERS = ("M", "dupper", "dlower", "Rinv", "v", "sense", "scaling", "RinvD")
_ITERATES = ("x", "xold", "lam", "lam_star", "u")


class WorkspaceHead(ctypes.Structure):
    """``DAQPWorkspace``, every field (``types.h``): its size is what is allocated."""

    _fields_ = [
        ("qp", ctypes.c_void_p),
        ("n", ctypes.c_int),
        ("m", ctypes.c_int),
        ("ms", ctypes.c_int),
        *((name, ctypes.c_void_p) for name in _POINTERS),
        *((name, ctypes.c_void_p) for name in _ITERATES),
        ("fval", ctypes.c_double),
        ("L", ctypes.c_void_p),
        ("D", ctypes.c_void_p),
        ("xldl", ctypes.c_void_p),
        ("zldl", ctypes.c_void_p),
        ("reuse_ind", ctypes.c_int),
        ("WS", ctypes.c_void_p),
        ("n_active", ctypes.c_int),
        ("iterations", ctypes.c_int),
        ("sing_ind", ctypes.c_int),
        ("prox_mask", ctypes.c_void_p),
        ("n_prox", ctypes.c_int),
        ("soft_slack", ctypes.c_double),
        ("settings", ctypes.POINTER(Settings)),
        ("bnb", ctypes.c_void_p),
        ("outer_iter", ctypes.c_int),
        ("hierarchy", ctypes.c_void_p),
        ("avi", ctypes.c_void_p),
        ("eq", ctypes.c_void_p),
        ("timer", ctypes.c_void_p),
        ("Mu", ctypes.c_void_p),
        ("rho_ls", ctypes.c_void_p),
        ("rho_us", ctypes.c_void_p),
        ("w_ls", ctypes.c_void_p),
        ("w_us", ctypes.c_void_p),
        ("state", ctypes.c_int),
    ]


_SENSE_AT = WorkspaceHead.sense.offset
"""Byte offset of ``DAQPWorkspace.sense``, the constraints' states a warm update keeps."""
_QP_SENSE = ProblemData.sense.offset // 8
_RES_X, _RES_LAM = Result.x.offset // 8, Result.lam.offset // 8
_RES_FLAG, _RES_ITER = Result.exitflag.offset // 4, Result.iter.offset // 4
assert _RES_FLAG % 2 == 0 and _RES_ITER == _RES_FLAG + 1  # one int64 word: read as one
_RES_WORDS = ctypes.sizeof(Result) // 8
MISFITTED, UPDATE_FAILED, SOLVED, ACCEPTED = 0.0, 1.0, 2.0, 3.0
"""Stages of :func:`stacked_solve`'s values (and :func:`solve_dropped`'s: ``ACCEPTED``)."""
H_UPDATE, H_SOLVE, H_CLOCK, H_WORK, H_PROBLEM, H_RESULT, H_SENSE = range(7)
"""Slots of a :class:`Workspace`'s ``handles`` (int64): the addresses of ``daqp_update_ldp``,
``daqp_solve`` and the C library's ``clock_gettime``, of the workspace, the ``DAQPProblem``,
the ``DAQPResult`` and the set-up's ``sense``."""


class LayoutError(RuntimeError):
    """The loaded DAQP does not lay its structures out as this module mirrors them."""


@functools.cache
def _library() -> ctypes.CDLL:
    """The ``daqp`` extension module as a C library, its functions' prototypes declared."""
    import daqp  # here: solvers is imported without DAQP's module (see solvers.registry)

    lib = ctypes.CDLL(daqp.__file__)
    void_p = ctypes.c_void_p
    prototypes: dict[str, tuple[Any, list[Any]]] = {
        "allocate_daqp_settings": (None, [void_p]),
        "daqp_default_settings": (None, [ctypes.POINTER(Settings)]),
        "setup_daqp_main": (
            ctypes.c_int,
            [ctypes.POINTER(ProblemData), void_p, _c_float_p, ctypes.c_int],
        ),
        "free_daqp_workspace": (None, [void_p]),
        "free_daqp_ldp": (None, [void_p]),
        "daqp_primal_init_active": (None, [ctypes.POINTER(ProblemData), _c_float_p]),
        "daqp_set_primal_start": (None, [void_p, _c_float_p]),
    }
    for name, (restype, argtypes) in prototypes.items():
        function = getattr(lib, name)
        function.restype, function.argtypes = restype, argtypes
    return lib


@functools.cache
def _libc() -> ctypes.CDLL:
    libc = ctypes.CDLL(None)
    libc.calloc.restype, libc.calloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t] * 2
    libc.free.restype, libc.free.argtypes = None, [ctypes.c_void_p]
    return libc


_MISMATCHED: list[str] = []
"""Why a set-up found the workspace laid out otherwise (then nothing is called here again)."""


def available() -> bool:
    """Whether the installed ``daqp`` is one whose layout this module mirrors: a version of
    :data:`KNOWN_VERSIONS` whose default settings read through :class:`Settings` are the
    extension's own (checked once), and no set-up found its workspace laid out otherwise."""
    return not _MISMATCHED and _mirrored()


@functools.cache
def _mirrored() -> bool:
    try:
        version = importlib.metadata.version("daqp")
    except importlib.metadata.PackageNotFoundError:
        return False
    if version not in KNOWN_VERSIONS:
        return False
    try:
        import daqp

        lib = _library()
    except (ImportError, OSError, AttributeError):
        return False
    defaults = Settings()
    lib.daqp_default_settings(ctypes.byref(defaults))
    theirs = daqp.Model().settings
    mine = {name: getattr(defaults, name) for name, _ in Settings._fields_}
    return set(theirs) == set(mine) and all(
        theirs[k] == mine[k] or (math.isnan(theirs[k]) and math.isnan(mine[k])) for k in mine
    )


def _address(array: np.ndarray | None) -> int:
    return 0 if array is None or array.size == 0 else int(array.ctypes.data)


class Workspace:
    """A DAQP workspace set up on the buffers given, as ``daqp.Model.setup`` does.

    Parameters
    ----------
    H, f, M, upper, lower
        DAQP's data (float64, C-contiguous; kept by reference, rewritten in place by the
        caller between solves): ``H`` (n, n), ``f`` (n,), ``M`` (rows of ``[G; A]``, n),
        ``upper`` and ``lower`` (ms + rows,).
    sense
        (ms + rows,) intc: the constraints' states at set-up (equality rows 5), kept.
    settings
        ``daqp.Model().settings`` keys and values.
    primal_start
        (n,) primal iterate to start from, or None.

    Attributes
    ----------
    x, lam : ndarray
        (n,), (ms + rows,): where every solve writes its answer, zeros at first and kept from
        solve to solve, as ``daqp.Model``'s: DAQP leaves them as they were when it has no
        answer (exit flag <= 0).
    words : ndarray of int64
        The ``DAQPProblem`` and then the ``DAQPResult`` :func:`solve_stacked` writes.
    flag : int
        ``setup_daqp_main``'s exit flag (< 0: the set-up failed; nothing may be solved).
    handles : ndarray of int64
        What :func:`solve_stacked` calls and reads (slots ``H_*``).
    """

    def __init__(
        self,
        H: np.ndarray,
        f: np.ndarray,
        M: np.ndarray,
        upper: np.ndarray,
        lower: np.ndarray,
        sense: np.ndarray,
        settings: dict[str, Any],
        primal_start: np.ndarray | None = None,
    ) -> None:
        self._work: int | None = None
        if not available():
            raise LayoutError(f"daqp {importlib.metadata.version('daqp')} is not mirrored here")
        lib = _library()
        self._kept = [H, f, M, upper, lower, sense]
        self.x, self.lam = np.zeros(f.shape[0]), np.zeros(upper.shape[0])
        given = sense.copy() if primal_start is not None else sense  # DAQP marks the start's
        self.words = np.zeros(ctypes.sizeof(ProblemData) // 8 + _RES_WORDS, dtype=np.int64)
        p = self.problem = ProblemData.from_buffer(self.words)
        p.n, p.m, p.ms = f.shape[0], upper.shape[0], upper.shape[0] - M.shape[0]
        p.H, p.f = (ctypes.cast(_address(a), _c_float_p) for a in (H, f))
        p.A = ctypes.cast(_address(M) if M.shape[0] else 0, _c_float_p)
        p.bupper, p.blower = (
            ctypes.cast(_address(a) if p.m else 0, _c_float_p) for a in (upper, lower)
        )
        self._given = given
        p.sense = ctypes.cast(_address(given) if p.m else 0, _c_int_p)
        head = self._allocate(settings)
        if primal_start is not None:
            start = np.ascontiguousarray(primal_start, dtype=np.float64)
            lib.daqp_primal_init_active(ctypes.byref(p), start.ctypes.data_as(_c_float_p))
        setup_time = ctypes.c_double(0.0)
        kept = Settings.from_buffer_copy(head.settings.contents)
        given_settings = ctypes.cast(head.settings, ctypes.c_void_p).value
        self.flag = int(
            lib.setup_daqp_main(ctypes.byref(p), self._work, ctypes.byref(setup_time), 0)
        )
        if self.flag < 0:  # DAQP let go of the settings it was given (not freed: daqp.Model
            _libc().free(given_settings)  # leaks them), then as daqp.Model allocate them again
            lib.allocate_daqp_settings(self._work)
        ctypes.memmove(head.settings, ctypes.byref(kept), ctypes.sizeof(Settings))
        if self.flag < 0:
            return
        if head.qp != ctypes.addressof(p) or (head.n, head.m, head.ms) != (p.n, p.m, p.ms):
            self._mismatch("the workspace does not name its problem where expected")
        if primal_start is not None:
            lib.daqp_set_primal_start(self._work, start.ctypes.data_as(_c_float_p))
        self.handles = np.array(
            [
                ctypes.cast(lib.daqp_update_ldp, ctypes.c_void_p).value,
                ctypes.cast(lib.daqp_solve, ctypes.c_void_p).value,
                clock.address(),
                self._work,
                ctypes.addressof(p),
                self.words.ctypes.data + ctypes.sizeof(ProblemData),
                _address(sense),
            ],
            dtype=np.int64,
        )

    def _allocate(self, settings: dict[str, Any]) -> WorkspaceHead:
        """A zeroed workspace with DAQP's settings, ``settings`` written over its defaults
        (after checking that the settings are the one field DAQP wrote)."""
        lib, libc = _library(), _libc()
        self._frees = (lib.free_daqp_workspace, lib.free_daqp_ldp, libc.free)  # kept: __del__
        size = max(ctypes.sizeof(WorkspaceHead), 1024)
        self._work = libc.calloc(1, size)
        if not self._work:
            raise MemoryError("could not allocate a DAQP workspace")
        lib.allocate_daqp_settings(self._work)
        words = np.ctypeslib.as_array((ctypes.c_int64 * (size // 8)).from_address(self._work))
        if np.flatnonzero(words).tolist() != [WorkspaceHead.settings.offset // 8]:
            self._mismatch("the settings are not where expected")
        head = WorkspaceHead.from_address(self._work)
        kinds = dict(Settings._fields_)
        for key, value in settings.items():
            whole = kinds[key] is ctypes.c_int and isinstance(value, float) and value.is_integer()
            setattr(head.settings.contents, key, int(value) if whole else value)  # as Cython
        return head

    def _mismatch(self, why: str) -> None:
        """Free the workspace, call nothing here again (:func:`available`), raise."""
        _MISMATCHED.append(why)
        self.close()
        raise LayoutError(f"DAQP's workspace is laid out otherwise: {why}")

    def __copy__(self) -> Workspace:
        raise TypeError("a DAQP workspace cannot be copied (it owns DAQP's memory)")

    def __deepcopy__(self, memo: dict[int, Any]) -> Workspace:
        raise TypeError("a DAQP workspace cannot be copied (it owns DAQP's memory)")

    def __reduce__(self) -> Any:
        raise TypeError("a DAQP workspace cannot be pickled (it owns DAQP's memory)")

    def close(self) -> None:
        """Free DAQP's memory (as ``daqp.Model``'s deallocation does); idempotent."""
        if getattr(self, "_work", None):
            free_workspace, free_ldp, free = self._frees
            free_workspace(self._work)
            free_ldp(self._work)
            free(self._work)
            self._work = None

    def __del__(self) -> None:
        self.close()


@intrinsic
def _read_word(typingctx, address):  # type: ignore[no-untyped-def]
    """The int64 at ``address``."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        pointer = builder.inttoptr(args[0], ir.IntType(64).as_pointer())
        return builder.load(pointer)

    return types.int64(types.int64), codegen


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
    x: np.ndarray,
    lam: np.ndarray,
) -> tuple[float, ...]:
    """Copy a problem into the set-up's ``data`` (:func:`solvers._fast.stack_into`), update
    DAQP's LDP as ``daqp.Model.update(H, f, A)`` does, solve into ``x`` (n,) and ``lam``
    (ms + p + m,), and check the answer on ``data``.

    ``handles`` and ``words`` are a :class:`Workspace`'s ``handles`` and the words behind its
    problem and result; ``mode`` holds the bits :data:`RESTART`, :data:`REFACTOR` and
    :data:`AS_SET_UP` (none: warm, from the working set of the last solve).

    Returns
    -------
    tuple of 12 floats
        ``(stage, flag, iterations, seconds, *values)``: stage :data:`MISFITTED` a size
        misfits (nothing done), :data:`UPDATE_FAILED` (``flag`` its exit flag), or
        :data:`SOLVED` (``flag`` DAQP's exit flag); ``seconds`` inside DAQP's update and
        solve; ``values`` those of
        :func:`solvers._kkt.stacked` (NaN unless solved).
    """
    nan = math.nan
    rows = ms + p + m
    if x.shape[0] != n or lam.shape[0] != rows:
        return (MISFITTED, nan, nan, 0.0, *MISFITTING)
    changed = 0 if mode & AS_SET_UP else stack_into(P, q, A, b, G, h, lb, ub, data, n, p, m, ms)
    if changed < 0:
        return (MISFITTED, nan, nan, 0.0, *MISFITTING)
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
    return (SOLVED, float(exitflag), float(iterations), spent, *values)


@compiled_on_first_call(
    _VALUES(
        *(_MAT_IN, _VEC_IN) * 3,
        _VEC_IN,
        _VEC_IN,
        _VEC_OUT,
        _WORDS,
        _WORDS,
        *(types.int64,) * 6,
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
    x: np.ndarray,
    lam: np.ndarray,
) -> tuple[float, ...]:
    """:func:`stacked_solve`, compiled for its one signature, called from Python."""
    return stacked_solve(
        P, q, A, b, G, h, lb, ub, data, handles, words, n, p, m, ms, flags, mode, x, lam
    )


@dataclass(frozen=True)
class AttemptCall:
    """What a solve's first attempt in compiled code needs (:func:`solve_dropped`): the bound
    problem's arrays (``P`` .. ``ub``, absent blocks as empty arrays), the set-up's ``data``,
    ``handles`` and ``words``, its sizes and ``flags`` (:func:`stacked_solve`'s), the
    attempt's ``mode`` ((1,): :data:`WARM` or :data:`RESTART`), the check's ``tolerance``
    (:func:`solvers.residuals.accepts`), and buffers for the answer
    ``x`` (n,) and ``lam`` (ms + p + m,). Valid
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
    x: np.ndarray
    lam: np.ndarray


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
    c = w.call
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
        c.x,
        c.lam,
    )
    if out[0] == SOLVED and accepts(out[4:], c.tolerance):
        return (ACCEPTED, *out[1:])
    return out
