"""Typed readers of parsed TOML tables for :mod:`dvqp.scenes.scene` (private).

Every reader takes the table, the key and the dotted path of the table (``"obstacles[1]"``)
and raises :class:`~dvqp.errors.SceneError` naming the full field on a missing, mistyped,
unknown or out-of-range entry (a number's sane range: a :class:`Bound`, :data:`ANY` if none).
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from decimal import Decimal
from typing import Any, NoReturn

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import DvqpError, ParameterError, SceneError, ShapeError

REQUIRED: Any = object()
"""Sentinel default: the field must be present."""


@dataclass(frozen=True)
class Bound:
    """The sane range of a physical quantity: ``low <= x <= high`` (``low < x`` if ``strict``);
    ``unit`` (``"m"``, ``"rad/s"``) is shown in messages after a non-zero bound."""

    low: float
    high: float
    unit: str = ""
    strict: bool = False

    def reason(self, value: float) -> str | None:
        """Why ``value`` is out of range (``"must be <= 100 m, got 1e+300"``), or None.

        ``value`` may be an integer too large for a float.
        """
        got = repr(value) if isinstance(value, float) else f"{Decimal(value):.4g}"
        if value < self.low or (self.strict and value == self.low):
            return f"must be {'>' if self.strict else '>='} {self._show(self.low)}, got {got}"
        if value > self.high:
            return f"must be <= {self._show(self.high)}, got {got}"
        return None

    def _show(self, bound: float) -> str:
        return f"{bound:g} {self.unit}" if bound and self.unit else f"{bound:g}"


ANY = Bound(-1e6, 1e6)
"""The range of a number whose field declares none."""


def join(prefix: str, key: str | int) -> str:
    """The dotted path of ``key`` in the table at ``prefix`` (``"a.b"``, ``"a[0]"``)."""
    if isinstance(key, int):
        return f"{prefix}[{key}]"
    return f"{prefix}.{key}" if prefix else key


KINDS = (
    (bool, "a boolean"),
    ((int, float), "a number"),
    (str, "a string"),
    (list, "an array"),
    (dict, "a table"),
)


def kind(value: object) -> str:
    """The TOML type of a parsed value, with an article (``"a string"``)."""
    return next((name for types, name in KINDS if isinstance(value, types)), "a date/time")


def is_number(value: object) -> bool:
    """True for TOML integers and floats (not booleans)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class Fields:
    """Readers bound to one scene ``source``: the file name (or ``"<string>"``) in every
    message."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, field: str, reason: str) -> NoReturn:
        """Raise ``SceneError(source, field, reason)``."""
        raise SceneError(self.source, field, reason)

    @contextmanager
    def mapped(self, prefix: str) -> Iterator[None]:
        """Re-raise constructor errors (ShapeError, ParameterError) as SceneError at prefix."""
        try:
            yield
        except ShapeError as exc:
            expected = "×".join("n" if e < 0 else str(e) for e in exc.expected)
            self.fail(join(prefix, exc.name), f"expected shape ({expected}), got {exc.actual}")
        except ParameterError as exc:
            self.fail(join(prefix, exc.name), exc.reason)

    @contextmanager
    def guard(self, prefix: str) -> Iterator[None]:
        """Report anything that escapes the field checks while reading ``prefix`` as SceneError.

        Constructor errors are mapped as in :meth:`mapped`, any other dvqp error keeps its
        message; an overflow, a NumPy floating-point error (raised here, not warned), a
        recursion too deep or a stray ``ValueError`` becomes ``cannot be used (<reason>)``.
        """
        try:
            with np.errstate(over="raise", divide="raise", invalid="raise"), self.mapped(prefix):
                yield
        except SceneError:
            raise
        except DvqpError as exc:
            self.fail(prefix, str(exc))
        except (ArithmeticError, RecursionError, ValueError, MemoryError) as exc:
            self.fail(prefix, f"cannot be used ({type(exc).__name__}: {exc})")

    def check_keys(self, table: dict[str, Any], prefix: str, allowed: Sequence[str]) -> None:
        """Reject keys of ``table`` not in ``allowed`` (typos), suggesting the closest one."""
        for key in table:
            if key not in allowed:
                close = difflib.get_close_matches(key, allowed, n=1)
                hint = f"did you mean {close[0]!r}?" if close else "allowed: " + ", ".join(allowed)
                self.fail(join(prefix, key), f"unknown key ({hint})")

    def get(self, table: dict[str, Any], key: str, prefix: str, default: Any = REQUIRED) -> Any:
        """The raw value, the default, or a 'required field is missing' error."""
        if key in table:
            return table[key]
        if default is REQUIRED:
            self.fail(join(prefix, key), "required field is missing")
        return default

    def table(
        self,
        parent: dict[str, Any],
        key: str,
        prefix: str,
        allowed: Sequence[str],
        *,
        required: bool = True,
    ) -> dict[str, Any]:
        """A sub-table with only ``allowed`` keys (``{}`` if optional and absent)."""
        value = self.get(parent, key, prefix, REQUIRED if required else {})
        if not isinstance(value, dict):
            self.fail(join(prefix, key), f"expected a table, got {kind(value)}")
        self.check_keys(value, join(prefix, key), allowed)
        return value

    def tables(
        self, parent: dict[str, Any], key: str, prefix: str, allowed: Sequence[str]
    ) -> list[dict[str, Any]]:
        """An array of tables (``[[key]]``), each with only ``allowed`` keys; ``[]`` if absent."""
        value = self.get(parent, key, prefix, [])
        field = join(prefix, key)
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            self.fail(field, f"expected an array of tables ([[{field}]]), got {kind(value)}")
        for i, item in enumerate(value):
            self.check_keys(item, join(field, i), allowed)
        return value

    def number(
        self,
        table: dict[str, Any],
        key: str,
        prefix: str,
        default: Any = REQUIRED,
        *,
        within: Bound = ANY,
    ) -> float:
        """A finite number (int or float) in ``within``, m / s / rad as documented per field."""
        return self._finite(join(prefix, key), self.get(table, key, prefix, default), within)

    def string(self, table: dict[str, Any], key: str, prefix: str, default: Any = REQUIRED) -> str:
        """A string."""
        value = self.get(table, key, prefix, default)
        if not isinstance(value, str):
            self.fail(join(prefix, key), f"expected a string, got {kind(value)}")
        return value

    def strings(self, table: dict[str, Any], key: str, prefix: str) -> list[str]:
        """A non-empty array of strings."""
        value = self.get(table, key, prefix)
        if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
            self.fail(join(prefix, key), f"expected an array of strings, got {kind(value)}")
        return value

    def vector(
        self,
        table: dict[str, Any],
        key: str,
        prefix: str,
        n: int,
        *,
        scalar: bool = False,
        default: Any = REQUIRED,
        infinite: bool = False,
        within: Bound | Sequence[Bound] = ANY,
    ) -> NDArray[np.float64]:
        """``n`` numbers (or one broadcast to ``n`` if ``scalar``), shape (n,), each in ``within``
        (one bound, or one per element) and finite unless ``infinite`` (then ``±inf`` pass as
        "no limit", ``nan`` does not)."""
        value = self.get(table, key, prefix, default)
        field = join(prefix, key)
        return self.vector_value(field, value, n, scalar=scalar, infinite=infinite, within=within)

    def vector_value(
        self,
        field: str,
        value: Any,
        n: int,
        *,
        scalar: bool = False,
        infinite: bool = False,
        within: Bound | Sequence[Bound] = ANY,
    ) -> NDArray[np.float64]:
        """Check an already fetched value as in :meth:`vector`."""
        bounds = [within] * n if isinstance(within, Bound) else list(within)
        if scalar and is_number(value):
            return np.full(n, self._finite(field, value, bounds[0], infinite))
        want = f"a number or an array of {n} numbers" if scalar else f"an array of {n} numbers"
        if not isinstance(value, list):
            self.fail(field, f"expected {want}, got {kind(value)}")
        if len(value) != n:
            self.fail(field, f"expected {want}, got {len(value)} values")
        items = enumerate(zip(value, bounds, strict=True))
        return np.array([self._finite(join(field, i), v, b, infinite) for i, (v, b) in items])

    def _finite(self, field: str, value: Any, within: Bound, infinite: bool = False) -> float:
        """``value`` as a float: a number, not NaN, finite unless ``infinite``, in ``within``."""
        if not is_number(value):
            self.fail(field, f"expected a number, got {kind(value)}")
        try:
            number = float(value)
        except OverflowError:  # an integer beyond 1.8e308
            self.fail(field, within.reason(value) or "out of range")
        if math.isnan(number) or (not infinite and math.isinf(number)):
            self.fail(field, f"must be finite, got {value!r}")
        reason = None if math.isinf(number) else within.reason(number)
        if reason is not None:
            self.fail(field, reason)
        return number
