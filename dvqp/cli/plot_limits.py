"""The limits page of a run: each limit's quantity over time against its bound.

One panel per kind of limit (:func:`dvqp.cli.limit_series.limit_series`): clearance per
obstacle, self distance, heights, tilt, then joint positions, speeds and accelerations as
fractions of their limits. The bound is a dashed red line with the forbidden side shaded; the
run's slowed, relaxed, braking, split and failed steps are shaded bands on every panel.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from dvqp._files import output_path
from dvqp.cli.figures import FIGURE_FORMATS, new_figure, save_figure
from dvqp.cli.limit_series import MARKS, Curve, LimitPage

if TYPE_CHECKING:
    from matplotlib.axes import Axes

MARK_COLOURS = {
    "slowed": "tab:olive",
    "relaxed": "tab:orange",
    "braking": "tab:blue",
    "split": "tab:purple",
    "failed": "tab:red",
}
"""The band colour of each kind of marked step."""

NAMED = 8
"""Curves a panel names in its legend, those that come closest to their bound; the others are
drawn thin and grey."""

TITLES = {
    "clearance": "clearance per obstacle (m)",
    "self distance": "self distance (m)",
    "height": "heights above the pipe (m)",
    "tilt": "probe tilt from radial (rad)",
    "joint position": "joint position, fraction of its half range from the middle",
    "joint speed": "joint speed |q̇|, fraction of q̇_max",
    "joint acceleration": "joint acceleration |q̈|, fraction of q̈_max",
    "task level error (m)": "task levels: worst length error from what each holds (m)",
    "task level error (rad)": "task levels: worst angle error from what each holds (rad)",
}


def plot_limits(page: LimitPage, path: str | Path, title: str = "") -> Path:
    """Draw ``page`` (one panel per kind of limit, two columns) and save it to ``path``
    (``.png``, ``.svg`` or ``.pdf``, written atomically; returned), titled ``title``.

    Raises
    ------
    ParameterError
        Unknown suffix or missing folder.
    DvqpError
        matplotlib is not installed.
    """
    target = output_path(path, FIGURE_FORMATS)
    panels = page.panels + page.level_panels
    rows = max(1, (len(panels) + 1) // 2)
    fig = new_figure((13.0, 2.9 * rows + 0.9))
    axes = fig.subplots(rows, 2, squeeze=False).ravel()
    span = (min(float(c.t[0]) for c in page.curves), max(float(c.t[-1]) for c in page.curves))
    curves = (*page.curves, *page.levels)
    for i, (ax, panel) in enumerate(zip(axes, panels, strict=False)):
        limit = panel in page.panels  # else a level's error: no bound
        _draw_panel(ax, panel, [c for c in curves if c.panel == panel], page, limit)
        ax.set_xlim(span[0], span[1] + page.dt)
        if i + 2 >= len(panels):  # the lowest panel of its column
            ax.set_xlabel("t (s)")
    for ax in axes[len(panels) :]:
        ax.set_axis_off()
    fig.legend(
        handles=_mark_handles(page),
        loc="outside lower center",
        ncol=len(MARKS) + 1,
        fontsize="small",
    )
    fig.suptitle(title or "limits over time: each quantity against its bound")
    return save_figure(fig, target, dpi=110)


def _draw_panel(
    ax: Axes, panel: str, curves: list[Curve], page: LimitPage, bounded: bool = True
) -> None:
    """The curves of one panel, their bounds (the forbidden side shaded; none if not
    ``bounded``) and the marks."""
    ranked = sorted(curves, key=lambda c: -float(np.max(c.past / max(abs(c.bound), 1e-3))))
    for rank, c in enumerate(ranked):
        step = "steps-post" if c.panel in ("joint speed", "joint acceleration") else "default"
        if rank < NAMED:
            ax.plot(c.t, c.values, lw=1.3, label=c.label, drawstyle=step, zorder=3)
        else:
            ax.plot(
                c.t,
                c.values,
                color="0.6",
                lw=0.7,
                drawstyle=step,
                zorder=2,
                label="others" if rank == NAMED else None,
            )
    bounds = dict.fromkeys((c.bound, c.upper) for c in curves) if bounded else {}
    bottom, top = ax.get_ylim()  # the bounds in view too, with room on their forbidden side
    low = min((b for b, _ in bounds), default=bottom)
    high = max((b for b, _ in bounds), default=top)
    pad = 0.08 * (max(top, high) - min(bottom, low))
    bottom, top = min(bottom, low - pad), max(top, high + pad)
    for bound, upper in bounds:
        ax.axhline(bound, color="tab:red", ls="--", lw=1.2, zorder=4)
        beyond = (bound, max(top, bound)) if upper else (min(bottom, bound), bound)
        ax.axhspan(*beyond, color="tab:red", alpha=0.08, lw=0, zorder=0)
    ax.set_ylim(bottom, top)
    _draw_marks(ax, page)
    ax.set_title(TITLES.get(panel, panel), fontsize="medium")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small", ncol=2 if len(curves) > 4 else 1, loc="best")


def _draw_marks(ax: Axes, page: LimitPage) -> None:
    """Each run of consecutive marked steps as one band over their duration, in its kind's
    colour."""
    for mark in MARKS:
        starts = page.marks[mark]
        cut = np.flatnonzero(np.diff(starts) > 1.5 * page.dt) + 1
        for run in np.split(starts, cut) if starts.shape[0] else ():
            ax.axvspan(
                run[0], run[-1] + page.dt, color=MARK_COLOURS[mark], alpha=0.25, lw=0, zorder=1
            )


def _mark_handles(page: LimitPage) -> list:
    """Legend entries: the bound and each kind of marked step, with its count."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles: list = [Line2D([], [], color="tab:red", ls="--", label="bound (shaded: past it)")]
    for mark in MARKS:
        count = page.marks[mark].shape[0]
        handles.append(Patch(color=MARK_COLOURS[mark], alpha=0.4, label=f"{mark} steps ({count})"))
    return handles
