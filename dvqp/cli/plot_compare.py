"""A figure of a backend comparison (the rows of :func:`dvqp.run.comparison.compare`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from dvqp._files import output_path
from dvqp.cli.figures import FIGURE_FORMATS, new_figure, save_figure

if TYPE_CHECKING:
    from dvqp.run.comparison import Row


def plot_comparison(rows: Sequence[Row], path: str | Path) -> Path:
    """Median step time and minimum clearance per scene and backend, as grouped bars.

    ``rows`` have at least ``scene``, ``backend``, ``median_step_us``, ``p95_step_us`` and
    ``min_clearance`` (m; None without obstacles). ``path`` (``.png``, ``.svg`` or ``.pdf``)
    is written atomically and returned.
    """
    target = output_path(path, FIGURE_FORMATS)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    backends = list(dict.fromkeys(r["backend"] for r in rows))
    by_key = {(r["scene"], r["backend"]): r for r in rows}
    fig = new_figure((max(8.0, 1.6 * len(scenes) + 3.0), 7.0))
    time_ax, clear_ax = fig.subplots(2, 1, sharex=True)
    width = 0.8 / max(len(backends), 1)
    x = np.arange(len(scenes))
    for k, backend in enumerate(backends):
        got = [by_key.get((s, backend), {}) for s in scenes]
        offset = x + (k - (len(backends) - 1) / 2) * width
        med, p95 = _column(got, "median_step_us"), _column(got, "p95_step_us")
        errors = [np.zeros_like(med), p95 - med]  # a bar from the median up to p95
        time_ax.bar(offset, med, width, label=backend, yerr=errors, capsize=2)
        clear_ax.bar(offset, 1000.0 * _column(got, "min_clearance"), width, label=backend)
    time_ax.set_yscale("log")
    time_ax.set_ylabel("full step time, µs (median, bar to p95)")
    time_ax.legend(ncol=min(len(backends), 5), fontsize="small")
    time_ax.set_title("dvqp compare: every backend on the same commands")
    clear_ax.axhline(0.0, color="k", lw=0.8)
    clear_ax.set_ylabel("min clearance to obstacles, mm")
    clear_ax.set_xticks(x, scenes, rotation=15)
    return save_figure(fig, target, dpi=120)


def _column(rows: Sequence[Row], key: str) -> NDArray[np.float64]:
    """``row[key]`` of every row as floats, NaN where missing or None."""
    return np.array([np.nan if r.get(key) is None else r[key] for r in rows], dtype=np.float64)
