"""What ``dvqp bench`` prints and writes: the summary table, the JSON document, the CSV.

Undefined figures (None) are ``-`` in the table, ``null`` in JSON (never NaN) and empty CSV
cells; flags are ``true``/``false`` in the CSV.
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from typing import Any

from dvqp._versions import versions
from dvqp.bench.execution import Where
from dvqp.bench.runner import EXTRA_FIELDS, Row
from dvqp.comparison import FIELDS, machine

COLUMNS = (  # (summary key, header, format of a defined value)
    ("runs", "runs", "{}"), ("succeeded", "ok", "{}"), ("success_rate", "success", "{:.1%}"),
    ("failed_steps", "failed steps", "{}"), ("relaxed_steps", "relaxed steps", "{}"),
    ("step_time_sgm_us", "step sgm us", "{:.0f}"), ("step_time_sgm_ratio", "x best", "{:.2f}"),
    ("solve_time_sgm_us", "solve sgm us", "{:.0f}"), ("solve_time_sgm_ratio", "x best", "{:.2f}"),
    ("worst_limit_excess", "worst excess", "{:.2g}"),
    ("worst_task_error", "worst task err", "{:.1e}"),
    ("max_distance_to_qp_median_m", "off QP median m", "{:.1e}"),
)  # fmt: skip
"""Columns of :func:`format_summary` after the backend's name."""

CSV_FIELDS = (
    "index", *(f for f in FIELDS if f != "index"), *(f for f in EXTRA_FIELDS if f != "index"),
    "final_l", "final_z", "final_h", "final_alpha", "parallel",
)  # fmt: skip
"""Columns of :func:`rows_to_csv`."""


@dataclass(frozen=True)
class Suite:
    """A finished (or interrupted) bench: what the outputs are made of.

    Attributes
    ----------
    seed, count : int
        The suite asked for.
    backends : tuple of str
        In the order they ran.
    where : Where
        Where the runs went.
    rows : list of dict
        One per finished scene and backend, by scene index then backend.
    summary : dict
        :func:`dvqp.bench.summary.summarize_backends`.
    disagreement : dict
        :func:`dvqp.bench.summary.qp_disagreement`.
    shift_us : float
        Shift of the shifted geometric means, µs.
    interrupted : bool
        Ctrl-C stopped it; ``rows`` holds the scenes finished before.
    """

    seed: int
    count: int
    backends: tuple[str, ...]
    where: Where
    rows: list[Row]
    summary: dict[str, dict[str, Any]]
    disagreement: dict[str, Any]
    shift_us: float
    interrupted: bool = False


def _cell(value: Any, fmt: str) -> str:
    return "-" if value is None else fmt.format(value)


def format_summary(suite: Suite) -> str:
    """The per-backend table and the notes under it (shift, timing, agreement)."""
    head = [["backend", *(h for _, h, _ in COLUMNS)]]
    body = [[b, *(_cell(suite.summary[b][k], f) for k, _, f in COLUMNS)] for b in suite.backends]
    table = head + body
    widths = [max(len(line[i]) for line in table) for i in range(len(head[0]))]
    lines = [
        "  ".join(
            c.ljust(w) if i == 0 else c.rjust(w)
            for i, (c, w) in enumerate(zip(line, widths, strict=True))
        )
        for line in table
    ]
    lines.insert(1, "  ".join("-" * w for w in widths))
    scenes = len({r["scene"] for r in suite.rows})
    timed = suite.summary[suite.backends[0]]["timed_scenes"] if suite.backends else 0
    d = suite.disagreement
    lines += [
        "",
        f"scenes          {scenes} of {suite.count} (seed {suite.seed}), {len(suite.rows)} runs"
        + (" (interrupted)" if suite.interrupted else ""),
        f"timing          {suite.where.describe()}",
        f"sgm             shifted geometric mean over the {timed} scenes every backend ran, of "
        f"each run's mean step time; shift {suite.shift_us:g} us; x best: over the fastest",
        "QP agreement    "
        + (
            f"final tool positions of successful QP runs differ by at most "
            f"{d['max_spread_m']:.2e} m ({d['scene']}: {' vs '.join(d['backends'])}; "
            f"{d['scenes_compared']} scenes compared)"
            if d["max_spread_m"] is not None
            else "no scene with two successful QP runs to compare"
        ),
    ]
    return "\n".join(lines)


def _clean(value: Any) -> Any:
    """``value`` with every non-finite float replaced by None (JSON has no NaN)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def _marked(suite: Suite) -> list[Row]:
    """The rows, each marked ``parallel`` when its timing came from workers side by side."""
    return [{**row, "parallel": suite.where.parallel} for row in suite.rows]


def bench_json(suite: Suite) -> str:
    """The ``--json`` document: results, summary, machine, versions, seed and count."""
    doc = {
        "seed": suite.seed, "count": suite.count, "backends": list(suite.backends),
        "interrupted": suite.interrupted, "execution": suite.where.as_dict(),
        "shift_us": suite.shift_us, "results": _marked(suite), "summary": suite.summary,
        "qp_disagreement": suite.disagreement, "machine": machine(), "versions": versions(),
    }  # fmt: skip
    return json.dumps(_clean(doc), indent=2, allow_nan=False) + "\n"


def rows_to_csv(suite: Suite) -> str:
    """One CSV line per scene and backend (:data:`CSV_FIELDS`), a header first."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(CSV_FIELDS)
    for row in _marked(suite):
        tool = row.get("final_tool") or [None] * 4
        names = ("final_l", "final_z", "final_h", "final_alpha")
        flat = {**row, **dict(zip(names, tool, strict=True))}
        writer.writerow([_csv_cell(flat.get(key)) for key in CSV_FIELDS])
    return buf.getvalue()


def _csv_cell(value: Any) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)
