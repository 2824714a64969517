"""Whether a part's compiled kernel computes what the part itself computes.

A subclass inherits its base's kernel, which computes its base's math: any override (of
``evaluate``, ``compute``, ``distances``, a private helper, ...) would make the compiled step
differ from the part. :func:`own_kernel` therefore trusts a kernel only where the part's own
class is one of dvqp's (its kernel is tested against its math) or defines the kernel itself (its
author wrote both); a subclass of either that does not define its own kernel takes the
reference path. A kernel factory raising ``NotImplementedError`` means the same.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def _trusted(cls: type, name: str) -> bool:
    """``cls`` is one of dvqp's own classes, or defines ``name`` itself."""
    return cls.__module__.split(".")[0] == "dvqp" or name in cls.__dict__


def own_kernel(part: Any, name: str) -> Callable[..., Any] | None:
    """``part.<name>`` (a kernel factory) if the kernel is the part's own (see the module
    docstring), else None (also when ``part`` has no such method)."""
    cls = part if isinstance(part, type) else type(part)
    if getattr(cls, name, None) is None or not _trusted(cls, name):
        return None
    return getattr(part, name)  # type: ignore[no-any-return]


def exact(part: Any, *classes: type) -> bool:
    """``part`` is an instance of one of ``classes`` exactly (not of a subclass, whose
    overrides the compiled step would not follow)."""
    return type(part) in classes


def build(part: Any, name: str, *args: Any) -> tuple[bool, Any]:
    """``(True, kernel-or-None)`` from ``part.<name>(*args)``, or ``(False, None)`` when the
    part has no kernel of its own math or its factory raises ``NotImplementedError``."""
    make = own_kernel(part, name)
    if make is None:
        return False, None
    try:
        return True, make(*args)
    except NotImplementedError:
        return False, None
