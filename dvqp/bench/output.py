"""What ``dvqp bench`` prints and writes: the summary table, the JSON document, the CSV.

Undefined figures (None) are ``-`` in the table, ``null`` in JSON (never NaN) and empty CSV
cells; flags are ``true``/``false`` in the CSV.
"""

from __future__ import annotations

import contextlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from dvqp._versions import versions
from dvqp.bench.execution import Where
from dvqp.bench.runner import EXTRA_FIELDS, Row, is_lost
from dvqp.run.comparison import FIELDS, machine
from dvqp.run.comparison import rows_to_csv as csv_text
from dvqp.run.table_text import aligned, cell

COLUMNS = (  # (summary key, header, format of a defined value)
    ("runs", "runs", "{}"),
    ("succeeded", "ok", "{}"),
    ("success_rate", "success", "{:.1%}"),
    ("failed_steps", "failed steps", "{}"),
    ("relaxed_steps", "relaxed steps", "{}"),
    ("capped_calls", "capped calls", "{}"),
    ("step_time_sgm_us", "step sgm us", "{:.0f}"),
    ("step_time_sgm_ratio", "x best", "{:.2f}"),
    ("solve_time_sgm_us", "solve sgm us", "{:.0f}"),
    ("solve_time_sgm_ratio", "x best", "{:.2f}"),
    ("worst_limit_excess", "worst excess", "{:.2g}"),
    ("worst_task_error", "worst task err", "{:.1e}"),
    ("max_distance_to_qp_median_m", "off QP median m", "{:.1e}"),
    ("primal_residual", "r_prim", "{:.1e}"),
    ("dual_residual", "r_dual", "{:.1e}"),
    ("duality_gap", "gap", "{:.1e}"),
)
"""Columns of :func:`format_summary` after the backend's name."""

TOOL = ("final_l", "final_z", "final_h", "final_alpha")
CSV_FIELDS = ("index", *FIELDS, *EXTRA_FIELDS, *TOOL, "parallel")
"""Columns of :func:`rows_to_csv`."""


@dataclass(frozen=True)
class Suite:
    """A finished (or ``interrupted`` by Ctrl-C) bench, what the outputs are made of: the
    ``seed`` and ``count`` asked for, the ``backends`` in the order they ran, ``where`` they ran,
    the ``rows`` of the finished scenes (by scene index, then backend), their ``summary``
    (:func:`~dvqp.bench.summary.summarize_backends`) and ``disagreement``
    (:func:`~dvqp.bench.summary.qp_disagreement`), and the sgm shift ``shift_us`` (µs)."""

    seed: int
    count: int
    backends: tuple[str, ...]
    where: Where
    rows: list[Row]
    summary: dict[str, dict[str, Any]]
    disagreement: dict[str, Any]
    shift_us: float
    interrupted: bool = False


def format_summary(suite: Suite) -> str:
    """The per-backend table and the notes under it (shift, timing, agreement)."""
    table = [["backend", *(h for _, h, _ in COLUMNS)]]
    table += [[b, *(cell(suite.summary[b][k], f) for k, _, f in COLUMNS)] for b in suite.backends]
    scenes = len({r["scene"] for r in suite.rows})
    lost = sorted({r["scene"] for r in suite.rows if is_lost(r)})
    timed = suite.summary[suite.backends[0]]["timed_scenes"] if suite.backends else 0
    d = suite.disagreement
    lines = [
        aligned(table),
        "",
        f"scenes          {scenes} of {suite.count} (seed {suite.seed}), {len(suite.rows)} runs"
        + (" (interrupted)" if suite.interrupted else ""),
        f"timing          {suite.where.describe()}",
        f"sgm             shifted geometric mean over the {timed} scenes every backend ran, of "
        f"each run's mean step time; shift {suite.shift_us:g} us; x best: over the fastest",
        f"accuracy        r_prim, r_dual, gap: shifted geometric means (shift 10) of every "
        f"step's QP answer's primal and dual residual and duality gap, {_tier(suite)} settings",
        "QP agreement    "
        + (
            f"final tool positions of successful QP runs differ by at most "
            f"{d['max_spread_m']:.2e} m ({d['scene']}: {' vs '.join(d['backends'])}; "
            f"{d['scenes_compared']} scenes compared)"
            if d["max_spread_m"] is not None
            else "no scene with two successful QP runs to compare"
        ),
    ]
    if lost:
        lines.append(
            f"lost            {len(lost)} scene{'s' * (len(lost) > 1)} (worker lost or "
            f"timed out: no figures): {', '.join(lost)}"
        )
    return "\n".join(lines)


def _tier(suite: Suite) -> str:
    """The settings tier the rows ran under (``default`` before any ran)."""
    return str(next((r["settings"] for r in suite.rows if r.get("settings")), "default"))


def _marked(suite: Suite) -> list[Row]:
    """The rows, each marked ``parallel`` when its timing came from workers side by side."""
    return [{**row, "parallel": suite.where.parallel} for row in suite.rows]


def bench_json(suite: Suite) -> str:
    """The ``--json`` document: results, summary, machine, versions, seed and count."""
    doc = {
        "seed": suite.seed,
        "count": suite.count,
        "backends": list(suite.backends),
        "interrupted": suite.interrupted,
        "execution": suite.where.as_dict(),
        "shift_us": suite.shift_us,
        "results": _marked(suite),
        "summary": suite.summary,
        "qp_disagreement": suite.disagreement,
        "machine": machine(),
        "versions": versions(),
    }
    clean = json.loads(json.dumps(doc), parse_constant=lambda _: None)  # NaN, ±inf: null
    return json.dumps(clean, indent=2, allow_nan=False) + "\n"


def rows_to_csv(suite: Suite) -> str:
    """One CSV line per scene and backend (:data:`CSV_FIELDS`, ``final_tool`` spread over
    :data:`TOOL`), a header first."""
    flat = [
        {**r, **dict(zip(TOOL, r.get("final_tool") or [None] * 4, strict=True))}
        for r in _marked(suite)
    ]
    return csv_text(flat, CSV_FIELDS)


class PartialFile:
    """``<output>.partial``: the results of each finished scene as JSON lines (one result a
    line, as in the JSON's ``results``), appended and flushed as the scene arrives, so that
    they outlive a process that is killed. :meth:`remove` it once the outputs are written."""

    def __init__(self, output: Path) -> None:
        self.path = output.with_name(output.name + ".partial")
        self._file: IO[str] | None = open(self.path, "w", encoding="utf-8")  # noqa: SIM115

    def add(self, rows: list[Row]) -> None:
        """Append one scene's ``rows`` (NaN and infinities as ``null``) and flush them."""
        if self._file is not None:
            clean = json.loads(json.dumps(rows), parse_constant=lambda _: None)
            self._file.write("".join(json.dumps(r, allow_nan=False) + "\n" for r in clean))
            self._file.flush()

    def remove(self) -> None:
        """Close and delete the file."""
        if self._file is not None:
            self._file.close()
            self._file = None
        with contextlib.suppress(OSError):
            self.path.unlink()
