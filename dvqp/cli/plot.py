"""Figures of a planned trajectory: developed view, heights and pipe cross-section.

Drawn and written atomically as :mod:`dvqp.cli.figures` does (matplotlib imported only when
called, no pyplot), from the building blocks of :mod:`dvqp.cli.drawing`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from dvqp._files import output_path
from dvqp.cli.drawing import (
    View,
    body_at,
    body_copies,
    draw_body,
    draw_developed_view,
    draw_section,
    make_view,
)
from dvqp.cli.figures import FIGURE_FORMATS, new_figure, save_figure, write_atomic
from dvqp.errors import ParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.cm import ScalarMappable
    from matplotlib.figure import Figure

    from dvqp.geometry.shapes import Shape
    from dvqp.motion.trajectory import Trajectory

__all__ = ["FIGURE_FORMATS", "animate_trajectory", "plot_trajectory"]


def plot_trajectory(
    traj: Trajectory,
    path: str | Path,
    *,
    obstacles: Sequence[Shape] = (),
    orbital_level: float | None = None,
    weld_z: float | None = None,
    min_height: float | None = None,
    instants: int = 6,
    full: bool = False,
) -> Path:
    """Draw a trajectory in three panels and save it (format from the suffix).

    Panels: (1) the developed view (l, z): seam, weld, obstacles, tool path and the body
    (points 1..k, then the tool) at ``instants`` evenly spaced times, coloured by time;
    (2) the heights h of the body points and the tool against time, and (dashed) the lowest
    point of the body's link chords and of the probe holder (if the trajectory has them);
    (3) the pipe cross-section (x, y) with the body at the same instants.

    Parameters
    ----------
    traj
        The trajectory (``pipe_radius`` must be set).
    path
        Output file, ``.png``, ``.svg`` or ``.pdf``; its folder must exist. Returned.
    obstacles
        Obstacle shapes (l, z) to draw.
    orbital_level, weld_z, min_height
        ``h*`` (m, a dashed line and circle), the axial position of a circumferential weld
        (m, dashed) and the body's lowest allowed height (m, a dotted line), drawn if given.
    instants
        Number of times at which the body is drawn, >= 1.
    full
        Draw the developed view's whole circumference; else only the arc where the arm and
        the obstacles are (:func:`dvqp.cli.drawing.arc_extent`).

    Raises
    ------
    ParameterError
        Unknown suffix, missing folder, or an invalid argument or trajectory.
    DvqpError
        matplotlib is not installed.
    """
    target = output_path(path, FIGURE_FORMATS)
    view = make_view(traj, obstacles, orbital_level, weld_z, min_height, full)
    _check_count("instants", instants, 1)
    top = float(np.clip(6.8 * view.aspect + 1.1, 2.2, 8.0))  # axes ~6.8 in wide
    fig = new_figure((11.0, top + 4.6))
    grid = fig.add_gridspec(2, 2, height_ratios=[top, 4.6], width_ratios=[1.3, 1.0])
    ax_dv, ax_h = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, 0])
    ax_x = fig.add_subplot(grid[1, 1])
    idx = _evenly(traj, instants)
    times = _time_scale(traj)
    _draw_developed_panel(fig, ax_dv, view, idx, times)
    _draw_heights(ax_h, view)
    draw_section(ax_x, view, [(i, times.to_rgba(traj.t[i])) for i in idx])
    failed = "" if traj.ok else f", {int(np.sum(~traj.success))} failed steps"
    fig.suptitle(
        f"dvqp trajectory ({traj.backend or 'unknown resolver'}): {traj.n_steps} steps, "
        f"{traj.t[-1]:.3g} s, R = {view.radius:.3g} m{failed}"
    )
    return save_figure(fig, target, dpi=150)


def animate_trajectory(
    traj: Trajectory,
    path: str | Path,
    *,
    obstacles: Sequence[Shape] = (),
    orbital_level: float | None = None,
    weld_z: float | None = None,
    min_height: float | None = None,
    fps: int = 20,
    max_frames: int = 120,
    full: bool = False,
) -> Path:
    """Save a GIF of the developed view with the body moving along the trajectory.

    ``path`` (``.gif``, in an existing folder) is returned; ``orbital_level`` is shown in the
    title. ``fps`` (> 0) frames a second, at most ``max_frames`` (>= 2) of them, the samples
    taken evenly, first and last included. The other arguments and the errors are as in
    :func:`plot_trajectory`.
    """
    target = output_path(path, (".gif",))
    view = make_view(traj, obstacles, orbital_level, weld_z, min_height, full)
    if isinstance(fps, bool) or not isinstance(fps, Real) or not 0 < fps < math.inf:
        raise ParameterError("fps", f"must be > 0, got {fps!r}")
    _check_count("max_frames", max_frames, 2)
    fig = new_figure((9.5, float(np.clip(6.0 * view.aspect + 1.2, 2.5, 9.0))))
    show = _animation_axes(fig, view)
    fig.canvas.draw()
    fig.set_layout_engine("none")  # freeze the layout: every frame has the same axes
    frames = _evenly(traj, min(max_frames, traj.t.shape[0]))
    return write_atomic(target, lambda tmp: _write_gif(fig, tmp, fps, frames, show))


def _time_scale(traj: Trajectory) -> ScalarMappable:
    """Colours by time: viridis over ``[t0, t_end]`` (s)."""
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    return ScalarMappable(norm=Normalize(t0, max(t1, t0 + 1e-9)), cmap=colormaps["viridis"])


def _draw_developed_panel(
    fig: Figure, ax: Axes, view: View, idx: NDArray[np.intp], times: ScalarMappable
) -> None:
    """The developed view with the body at samples ``idx``, its legend and the time bar."""
    draw_developed_view(ax, view)
    for n, i in enumerate(idx):
        colour = times.to_rgba(view.traj.t[i])
        rail = view.traj.rail.shape[0] > 0
        draw_body(ax, body_at(view.traj, i), view.radius, colour, legend=n == 0, rail=rail)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    cax = ax.inset_axes((1.03, 0.06, 0.24, 0.07))
    bar = fig.colorbar(times, cax=cax, orientation="horizontal")
    bar.set_label("body drawn at t (s)", fontsize="small")


def _draw_heights(ax: Axes, view: View) -> None:
    """Heights h (m) of the body points, the tool, the lowest link chord and the holder's
    lowest point against time, ``h*`` and ``min_height``."""
    traj = view.traj
    for j in range(traj.points.shape[1]):
        ax.plot(traj.t, traj.points[:, j, 2], lw=1.2, label=f"point {j + 1}")
    ax.plot(traj.t, traj.tool[:, 2], "k-", lw=1.6, label="tool")
    if traj.link_height.size:  # absent from files written before they were recorded
        ax.plot(traj.t, traj.link_height, "m--", lw=1.2, label="lowest link chord")
        ax.plot(traj.t, traj.holder_height, "k--", lw=1.2, label="holder, lowest")
    if view.h_star is not None:
        ax.axhline(view.h_star, color="0.3", ls="--", lw=1.2, label=f"h* = {view.h_star:.3g} m")
    if view.min_height is not None:
        ax.axhline(
            view.min_height,
            color="tab:red",
            ls=":",
            lw=1.4,
            label=f"min_height = {view.min_height:.3g} m",
        )
    ax.set(xlabel="t (s)", ylabel="h (m)", title="heights above the pipe surface")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=2)


def _animation_axes(fig: Figure, view: View) -> Callable[[int], None]:
    """Draw the first frame; return ``show(i)``, which moves the body to sample i."""
    ax = fig.add_subplot()
    draw_developed_view(ax, view)
    rail = view.traj.rail.shape[0] > 0
    artists = draw_body(ax, body_at(view.traj, 0), view.radius, "tab:red", rail=rail)
    stamp = ax.text(0.01, 0.97, "", transform=ax.transAxes, va="top", fontsize="small")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    level = "" if view.h_star is None else f", h* = {view.h_star:.3g} m"
    ax.set_title(ax.get_title() + level)

    def show(i: int) -> None:
        for j, (lb, zb) in enumerate(body_copies(body_at(view.traj, i), view.radius)):
            artists[2 * j].set_data(lb, zb)
            artists[2 * j + 1].set_data(lb[-1:], zb[-1:])
        stamp.set_text(f"t = {view.traj.t[i]:.2f} s")

    return show


def _write_gif(
    fig: Figure, tmp: str, fps: float, frames: NDArray[np.intp], show: Callable[[int], None]
) -> None:
    """Write the GIF to ``tmp``: one frame per sample of ``frames``, at ``fps``."""
    from matplotlib.animation import PillowWriter

    writer = PillowWriter(fps=fps)
    with writer.saving(fig, tmp, dpi=100):
        for i in frames:
            show(int(i))
            writer.grab_frame()


def _evenly(traj: Trajectory, count: int) -> NDArray[np.intp]:
    """Indices of ``count`` samples evenly spread over the trajectory, first and last included."""
    return np.unique(np.linspace(0, traj.t.shape[0] - 1, count).round().astype(int))


def _check_count(name: str, value: object, least: int) -> None:
    """Raise :class:`ParameterError` unless ``value`` is an integer >= ``least``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise ParameterError(name, f"must be an integer >= {least}, got {value!r}")
