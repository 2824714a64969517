"""``time.perf_counter``'s clock read in compiled code: ``now(address())`` seconds.

Linux's ``CLOCK_MONOTONIC``, the clock of ``time.perf_counter`` (the same seconds, so a time
taken inside a compiled call can be subtracted from one taken around it), read with the C
library's ``clock_gettime`` called at the address :func:`address` gives (about 20 ns).
"""

from __future__ import annotations

import ctypes
import functools

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.core.extending import intrinsic

from .jit import njit

CLOCK_MONOTONIC = 1
"""Linux's ``CLOCK_MONOTONIC``, the clock of ``time.perf_counter``."""


@functools.cache
def address() -> int:
    """The address of the C library's ``clock_gettime``, for :func:`now`."""
    return int(ctypes.cast(ctypes.CDLL(None).clock_gettime, ctypes.c_void_p).value or 0)


@intrinsic
def _read(typingctx, function):  # type: ignore[no-untyped-def]
    """``clock_gettime(CLOCK_MONOTONIC)`` (``function``: its address) in seconds."""

    def codegen(context, builder, sig, args):  # type: ignore[no-untyped-def]
        i64 = ir.IntType(64)
        spec = cgutils.alloca_once(builder, ir.ArrayType(i64, 2))
        fnty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), spec.type])
        callee = builder.inttoptr(args[0], fnty.as_pointer())
        builder.call(callee, [ir.Constant(ir.IntType(32), CLOCK_MONOTONIC), spec])
        zero = ir.Constant(ir.IntType(32), 0)
        parts = [
            builder.load(builder.gep(spec, [zero, ir.Constant(ir.IntType(32), i)])) for i in (0, 1)
        ]
        seconds, nanoseconds = (builder.sitofp(v, ir.DoubleType()) for v in parts)
        return builder.fadd(seconds, builder.fmul(nanoseconds, ir.Constant(ir.DoubleType(), 1e-9)))

    return types.float64(types.int64), codegen


@njit(inline="always")
def now(address: int) -> float:
    """The clock's seconds; ``address`` is :func:`address`'s."""
    return _read(address)  # type: ignore[no-any-return]
