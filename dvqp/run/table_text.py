"""Result rows as text: table cells, aligned columns, CSV (``compare`` and ``bench``)."""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from typing import Any

import numpy as np


def cell(value: Any, fmt: str = "{}") -> str:
    """A table cell: ``-`` for None, ``yes``/``NO`` for a flag, else ``fmt.format(value)``."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "NO"
    return fmt.format(value)


def aligned(table: Sequence[Sequence[str]], left: int = 1) -> str:
    """Rows of cells as text columns two spaces apart, a rule of ``-`` under the first row;
    the first ``left`` columns left-justified, the others right-justified."""
    widths = [max(len(line[i]) for line in table) for i in range(len(table[0]))]
    just = [str.ljust] * left + [str.rjust] * (len(widths) - left)
    lines = [
        "  ".join(j(c, w) for j, c, w in zip(just, line, widths, strict=True)) for line in table
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def csv_cell(value: Any) -> str:
    """A CSV cell: empty for None or a non-finite float, ``true``/``false`` for a flag."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return ""
    return str(value).lower() if isinstance(value, bool) else str(value)


def csv_text(rows: Sequence[dict[str, Any]], fields: Sequence[str]) -> str:
    """The rows as CSV text: a header of ``fields``, then one line per row (:func:`csv_cell`)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(fields)
    writer.writerows([csv_cell(row.get(key)) for key in fields] for row in rows)
    return buf.getvalue()
