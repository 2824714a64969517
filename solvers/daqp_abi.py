"""DAQP's structures as its C library lays them out, and a workspace set up through its API.

The ``daqp`` extension module exports DAQP's C API (``setup_daqp_main``, ``daqp_update_ldp``,
``daqp_solve``, ...). The ``ctypes`` structures below mirror DAQP's ``types.h`` and ``api.h``
of the versions in :data:`KNOWN_VERSIONS`, and of no other: :func:`available` is False for any
other version (the adapter then keeps ``daqp.Model``). Checks hold the mirror to the library
actually loaded: DAQP's default settings read through :class:`Settings` must equal
``daqp.Model().settings`` (the extension's own compiled layout), the settings pointer must be
the one field ``allocate_daqp_settings`` writes, and after each set-up the workspace must name
the problem and its sizes where :class:`WorkspaceHead` says. :class:`Workspace` allocates and
sets up a DAQP workspace as ``daqp.Model.setup`` does; :mod:`solvers.daqp_c` solves in it from
compiled code.
"""

from __future__ import annotations

import ctypes
import functools
import importlib.metadata
import math
from typing import Any

import numpy as np

from . import clock

KNOWN_VERSIONS = ("0.11.0",)
"""The ``daqp`` versions whose ``types.h`` the structures below mirror."""

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
_WS_AT, _ACTIVE_AT = WorkspaceHead.WS.offset, WorkspaceHead.n_active.offset
_LAM_STAR_AT, _SCALING_AT = WorkspaceHead.lam_star.offset, WorkspaceHead.scaling.offset
_EQ_AT = WorkspaceHead.eq.offset
"""Byte offsets of ``DAQPWorkspace.WS`` (int*), ``n_active`` (int), ``lam_star``
(c_float*) and ``scaling`` (c_float*): the working set and the dual direction DAQP leaves
when it finds a problem infeasible (:mod:`solvers.daqp_c`); and of ``eq`` (set when DAQP
eliminates equalities: the workspace then describes the reduced problem)."""
_QP_SENSE = ProblemData.sense.offset // 8
_RES_X, _RES_LAM = Result.x.offset // 8, Result.lam.offset // 8
_RES_FLAG, _RES_ITER = Result.exitflag.offset // 4, Result.iter.offset // 4
assert _RES_FLAG % 2 == 0 and _RES_ITER == _RES_FLAG + 1  # one int64 word: read as one
_RES_WORDS = ctypes.sizeof(Result) // 8
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
        solve to solve, as ``daqp.Model``'s. When DAQP has no answer (exit flag <= 0) it
        writes its last iterate into ``x`` and nothing into ``lam``.
    ray : ndarray
        (ms + rows,): DAQP's infeasibility direction of the last refusal it found, which
        :func:`solvers.daqp_c.stacked_solve` reads from the workspace (zeros until then).
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
        self.ray = np.zeros(upper.shape[0])  # DAQP's direction of a refusal (solvers.daqp_c)
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
        self.handles = self._handles(lib, sense)

    def _handles(self, lib: ctypes.CDLL, sense: np.ndarray) -> np.ndarray:
        """What :func:`solvers.daqp_c.stacked_solve` calls and reads (slots ``H_*``)."""
        return np.array(
            [
                ctypes.cast(lib.daqp_update_ldp, ctypes.c_void_p).value,
                ctypes.cast(lib.daqp_solve, ctypes.c_void_p).value,
                clock.address(),
                self._work,
                ctypes.addressof(self.problem),
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
