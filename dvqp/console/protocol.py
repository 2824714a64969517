"""The console's WebSocket protocol (``docs/console.md``): client messages checked and
clamped, and the JSON sent back. Nothing here imports the web framework.

A client sends one JSON object per text frame: ``jog`` (a velocity ``[l̇, ż, ḣ, α̇]`` held
until the next message, clamped to :data:`SPEED_LIMITS`), ``stop`` or ``reset``. Anything else
raises :class:`ProtocolError`, whose one-line message the server sends back as an ``error``
message; nothing changes.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import one_line

MAX_MESSAGE_BYTES = 4096
"""Largest client message answered, bytes (UTF-8); a longer one gets an ``error`` reply."""
MAX_LINEAR_SPEED = 0.1
"""Largest JOG speed of l, z and h, m/s; a faster command is clamped to it."""
MAX_ANGULAR_SPEED = 1.0
"""Largest JOG speed of the heading α, rad/s; a faster command is clamped to it."""
SPEED_LIMITS = np.array([MAX_LINEAR_SPEED] * 3 + [MAX_ANGULAR_SPEED])
AXES = ("l", "z", "h", "alpha")
UNITS = ("m/s", "m/s", "m/s", "rad/s")
KEYS = {"jog": {"type", "velocity"}, "stop": {"type"}, "reset": {"type"}}


class ProtocolError(ValueError):
    """A client message the console refuses; ``str(error)`` is the one-line reply."""


@dataclass(frozen=True)
class Message:
    """A checked client message: its ``kind`` (``"jog"``, ``"stop"`` or ``"reset"``) and the
    JOG ``velocity`` as sent, shape (4,) (zeros for ``stop`` and ``reset``)."""

    kind: str
    velocity: NDArray[np.float64]


def _no_constant(name: str) -> float:
    raise ProtocolError(f"{name} is not a number: values must be finite")


def parse(data: str | bytes) -> Message:
    """Check one client message: :class:`ProtocolError` if it is too long, not JSON, not a
    known message, or has a velocity that is not 4 finite numbers."""
    if not isinstance(data, str):
        raise ProtocolError("binary frames are not accepted: send JSON text")
    size = len(data.encode("utf-8", "surrogatepass"))
    if size > MAX_MESSAGE_BYTES:
        raise ProtocolError(f"message too long: {size} bytes (at most {MAX_MESSAGE_BYTES})")
    try:
        doc = json.loads(data, parse_constant=_no_constant)
    except ProtocolError:
        raise
    except (ValueError, RecursionError) as exc:
        raise ProtocolError(f"not JSON: {str(exc).splitlines()[0][:120]}") from None
    if not isinstance(doc, dict):
        raise ProtocolError(f"expected a JSON object, got {type(doc).__name__}")
    kind = doc.get("type")
    if not isinstance(kind, str) or kind not in KEYS:
        raise ProtocolError(f"unknown message type {_show(kind)} (known: jog, stop, reset)")
    extra = sorted(set(doc) - KEYS[kind])
    if extra:
        raise ProtocolError(f"{kind}: unknown key {_show(extra[0])}")
    return Message(kind, _velocity(doc.get("velocity")) if kind == "jog" else np.zeros(4))


def _velocity(value: Any) -> NDArray[np.float64]:
    """Four finite numbers (booleans are not numbers)."""
    if not isinstance(value, list) or len(value) != 4:
        raise ProtocolError("jog: velocity must be an array of 4 numbers [l, z, h, alpha]")
    for axis, v in zip(AXES, value, strict=True):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ProtocolError(f"jog: velocity {axis}: expected a number, got {_show(v)}")
        try:
            finite = math.isfinite(v)
        except OverflowError:  # an integer too large for a float
            finite = False
        if not finite:
            raise ProtocolError(f"jog: velocity {axis}: must be finite, got {_show(v)}")
    return np.array(value, dtype=np.float64)


def clamp(velocity: NDArray[np.float64]) -> tuple[NDArray[np.float64], str | None]:
    """The velocity within the JOG speed limits, and a note naming what was clamped (or None)."""
    applied = np.clip(velocity, -SPEED_LIMITS, SPEED_LIMITS)
    clamped = [
        f"{axis} {v:.3g} -> {a:.3g} {unit}"
        for axis, unit, v, a in zip(AXES, UNITS, velocity, applied, strict=True)
        if v != a
    ]
    return applied, ("clamped: " + ", ".join(clamped)) if clamped else None


def _show(value: Any) -> str:
    """A short printable form of a client's value for an error message."""
    text = json.dumps(value, allow_nan=True, default=str)
    return text if len(text) <= 40 else text[:37] + "..."


def finite(value: float, digits: int = 6) -> float | None:
    """``value`` rounded, or None where it is not finite (JSON has no inf or NaN)."""
    return round(float(value), digits) if math.isfinite(value) else None


def rounded(values: Any, digits: int = 6) -> list[Any]:
    """A nested list of rounded finite numbers (None for the others)."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 0:
        return finite(float(array), digits)  # type: ignore[return-value]
    return [rounded(v, digits) for v in array]


def encode(message: dict[str, Any]) -> str:
    """Compact JSON without inf or NaN."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False)


def error(message: str) -> str:
    """The ``error`` reply (unprintable characters escaped: the page shows it as text)."""
    return encode({"type": "error", "message": one_line(message)})
