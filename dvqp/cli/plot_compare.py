"""A figure of a backend comparison (the rows of :func:`dvqp.compare.compare`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from dvqp._files import output_path
from dvqp.cli.plot import FIGURE_FORMATS, _atomic, _figure


def plot_comparison(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Median step time and minimum clearance per scene and backend, as grouped bars.

    Parameters
    ----------
    rows
        Result rows with at least ``scene``, ``backend``, ``median_step_us``,
        ``p95_step_us`` and ``min_clearance`` (m; None without obstacles).
    path
        ``.png``, ``.svg`` or ``.pdf``; written atomically.
    """
    target = output_path(path, FIGURE_FORMATS)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    backends = list(dict.fromkeys(r["backend"] for r in rows))
    by_key = {(r["scene"], r["backend"]): r for r in rows}
    fig = _figure((max(8.0, 1.6 * len(scenes) + 3.0), 7.0))
    time_ax, clear_ax = fig.subplots(2, 1, sharex=True)
    width = 0.8 / max(len(backends), 1)
    x = np.arange(len(scenes))
    for k, backend in enumerate(backends):
        get = [by_key.get((s, backend), {}) for s in scenes]
        med = np.array(
            [np.nan if r.get("median_step_us") is None else r["median_step_us"] for r in get]
        )
        p95 = np.array([np.nan if r.get("p95_step_us") is None else r["p95_step_us"] for r in get])
        clear = np.array(
            [np.nan if r.get("min_clearance") is None else r["min_clearance"] for r in get]
        )
        offset = x + (k - (len(backends) - 1) / 2) * width
        time_ax.bar(
            offset, med, width, label=backend, yerr=[np.zeros_like(med), p95 - med], capsize=2
        )
        clear_ax.bar(offset, 1000.0 * clear, width, label=backend)
    time_ax.set_yscale("log")
    time_ax.set_ylabel("full step time, µs (median, bar to p95)")
    time_ax.legend(ncol=min(len(backends), 5), fontsize="small")
    time_ax.set_title("dvqp compare: every backend on the same commands")
    clear_ax.axhline(0.0, color="k", lw=0.8)
    clear_ax.set_ylabel("min clearance to obstacles, mm")
    clear_ax.set_xticks(x, scenes, rotation=15)
    return _atomic(target, lambda tmp: fig.savefig(tmp, format=target.suffix[1:], dpi=120))
