"""Whether a part's compiled kernel computes what the part itself computes.

A subclass that overrides a part's math (``evaluate``, ``compute``, ``distances``, ...) but not
its ``kernel`` would inherit a kernel of its base's math. :func:`own_kernel` gives the kernel
method only if the class that defines it is at least as derived as every class that defines
the part's math; otherwise (and when the kernel says it cannot be built by raising
``NotImplementedError``) the run takes the reference path.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

TASK = ("compute",)
TERM = ("evaluate",)
LIMIT = ("compute", "distances", "all_distances")
VERIFIED = ("excess", "distances", "all_distances")
SHAPE = ("point_distance", "segment_distance", "batch_points", "batch_segments", "penalty",
         "size")  # fmt: skip


def _owner(cls: type, name: str) -> type | None:
    for c in cls.__mro__:
        if name in c.__dict__:
            return c
    return None


def own_kernel(part: Any, name: str, math: tuple[str, ...]) -> Callable[..., Any] | None:
    """``part.<name>`` (a kernel factory) if it covers every method in ``math`` that ``part``'s
    class defines, else None (also when ``part`` has no such method)."""
    cls = part if isinstance(part, type) else type(part)
    owner = _owner(cls, name)
    if owner is None:
        return None
    for method in math:
        defined = _owner(cls, method)
        if defined is not None and not issubclass(owner, defined):
            return None
    return getattr(part, name)  # type: ignore[no-any-return]


def build(part: Any, name: str, math: tuple[str, ...], *args: Any) -> tuple[bool, Any]:
    """``(True, kernel-or-None)`` from ``part.<name>(*args)``, or ``(False, None)`` when the
    part has no kernel of its own math or its factory raises ``NotImplementedError``."""
    make = own_kernel(part, name, math)
    if make is None:
        return False, None
    try:
        return True, make(*args)
    except NotImplementedError:
        return False, None
