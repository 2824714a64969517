"""Write a generated scene, a nested dict, as TOML text: strings, booleans, integers, floats
and (nested) arrays of them, tables and arrays of flat tables, the subset scene files use.
Floats are written with ``repr``, so reading the text back gives exactly the same numbers.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from dvqp.errors import ParameterError

Table = dict[str, Any]


def dumps(doc: Table, comment: str = "") -> str:
    """``doc`` as TOML text, an optional ``# comment`` block first; ParameterError for a value
    TOML (or this writer) cannot hold: NaN, infinity, an unknown type."""
    lines = [f"# {line}" if line else "#" for line in comment.splitlines()]
    _table(lines, (), doc)
    return "\n".join(lines).strip("\n") + "\n"


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _table(lines: list[str], path: tuple[str, ...], table: Table) -> None:
    """Append ``[path]``, its plain keys, then its sub-tables and arrays of tables."""
    plain = {k: v for k, v in table.items() if not isinstance(v, dict) and not _is_table_array(v)}
    if path and (plain or not table):
        lines += ["", f"[{'.'.join(path)}]"]
    lines += [f"{key} = {value_text(value)}" for key, value in plain.items()]
    for key, value in table.items():
        if isinstance(value, dict):
            _table(lines, (*path, key), value)
        elif _is_table_array(value):
            for item in value:
                lines += ["", f"[[{'.'.join((*path, key))}]]"]
                lines += [f"{k} = {value_text(v)}" for k, v in item.items()]


def value_text(value: Any) -> str:
    """One TOML value: ``"text"``, ``true``, ``3``, ``0.254``, ``[0.1, 0.2]``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ParameterError("scene", f"cannot write {value!r} in a scene file")
        return repr(float(value))  # a NumPy float's repr is np.float64(...)
    if isinstance(value, str):
        return json.dumps(value)  # a TOML basic string for any printable text
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(value_text(v) for v in value) + "]"
    raise ParameterError("scene", f"cannot write a {type(value).__name__} in a scene file")
