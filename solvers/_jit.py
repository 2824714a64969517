"""Numba functions compiled for one declared signature at their first call, not at import."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numba import njit
from numba.core.dispatcher import Dispatcher
from numba.core.typing.templates import Signature


def compiled_on_first_call(
    signature: Signature, **options: Any
) -> Callable[[Callable[..., Any]], Dispatcher]:
    """``njit(signature, cache=True, **options)``, compiled at the first call, not at import.

    ``njit`` given a signature compiles it (or loads it from numba's on-disk cache) when the
    module is imported: seconds of CPU with an empty cache, in every process that imports
    ``solvers``, whether it solves anything or not. A plain lazy ``njit`` would instead compile
    one specialisation per distinct argument types, and writable and read-only arrays are
    distinct types: twice the compile time for a kernel called with both.

    The dispatcher returned compiles nothing until it is called. Its first call compiles
    ``signature`` alone (or loads it from the cache) and then disables compilation, as
    ``njit(signature)`` does at import: from then on, that first call included, arguments
    are converted to the signature (a writable array passes as a read-only one) or refused
    with ``TypeError``, and there is one specialisation, however the function is called.

    Parameters
    ----------
    signature : numba Signature
        The one signature to compile, e.g. ``types.boolean(types.float64[::1])``.
    **options
        Further ``njit`` options (e.g. ``fastmath``); ``cache=True`` is always set.

    Returns
    -------
    callable
        A decorator turning a function into its numba dispatcher.

    Notes
    -----
    The hook is the dispatcher's ``_compile_for_args``, which numba calls only when no compiled
    overload fits the arguments and compilation is enabled, i.e. only until the first call
    has compiled. Replacing it returns the dispatcher itself, which numba then calls again with
    the same arguments: now a typed call of the one overload. Concurrent first calls are safe
    (the second ``compile`` finds the overload the first one made). Meant for functions called
    from Python: numba's typing of a call from other jitted code would compile the callee for
    the caller's argument types instead. ``tests/test_solvers_structure.py`` checks, in a fresh
    interpreter, that importing compiles nothing and that each kernel ends with one overload.
    """

    def decorate(function: Callable[..., Any]) -> Dispatcher:
        dispatcher = njit(cache=True, **options)(function)

        def compile_declared(*args: Any, **kwargs: Any) -> Dispatcher:
            dispatcher.compile(signature)
            dispatcher.disable_compile()
            return dispatcher

        dispatcher._compile_for_args = compile_declared
        return dispatcher

    return decorate
