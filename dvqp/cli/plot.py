"""Figures of a planned trajectory: developed view, heights and pipe cross-section.

Needs matplotlib (``pip install 'dvqp[plot]'``), imported only when a function is called. The
figures are drawn on a :class:`matplotlib.figure.Figure` with the Agg canvas, never through
``pyplot``: no display and no backend setting are needed. Files are written atomically.

In the developed view, l is shown wrapped into ``(−πR, πR]``; the strips just beyond the seam
``l = ±πR`` (shaded) repeat the other side of the pipe, so obstacles, the tool path and the body
stay continuous where they cross the seam.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp._files import atomic_file, output_path
from dvqp.kinematics.developed_view import unwrap, wrap
from dvqp.errors import DvqpError, ParameterError
from dvqp.geometry.obstacle import Obstacle
from dvqp.motion.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FIGURE_FORMATS = (".png", ".svg", ".pdf")
"""Suffixes :func:`plot_trajectory` writes (:func:`animate_trajectory` writes ``.gif``)."""

_SHIFTS = (-1, 0, 1)  # copies of seam-periodic drawings, in periods 2πR


def plot_trajectory(
    traj: Trajectory,
    path: str | Path,
    *,
    obstacles: Sequence[Obstacle] = (),
    orbital_level: float | None = None,
    weld_z: float | None = None,
    instants: int = 6,
) -> Path:
    """Draw a trajectory in three panels and save it (format from the suffix).

    Panels: (1) the developed view (l, z): seam, weld, obstacles, tool path and the body
    (points 1..k, then the tool) at ``instants`` evenly spaced times, coloured by time;
    (2) the heights h of the body points and the tool against time; (3) the pipe
    cross-section (x, y) with the body at the same instants.

    Parameters
    ----------
    traj
        The trajectory (``pipe_radius`` must be set).
    path
        Output file, ``.png``, ``.svg`` or ``.pdf``; its folder must exist.
    obstacles
        Obstacle circles (l, z) to draw.
    orbital_level
        ``h*`` (m), drawn as a dashed line and circle if given.
    weld_z
        Axial position (m) of a circumferential weld, drawn dashed if given.
    instants
        Number of times at which the body is drawn, >= 1.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        Unknown suffix, missing folder, or an invalid argument or trajectory.
    DvqpError
        matplotlib is not installed.
    """
    target = output_path(path, FIGURE_FORMATS)
    sc = _scene(traj, obstacles, orbital_level, weld_z)
    _integer("instants", instants, 1)
    top = float(np.clip(7.6 * sc.aspect + 1.1, 2.2, 8.0))
    fig = _figure((11.0, top + 4.6))
    from matplotlib import colormaps
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    grid = fig.add_gridspec(2, 2, height_ratios=[top, 4.6], width_ratios=[1.3, 1.0])
    ax_dv, ax_h = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, 0])
    ax_x = fig.add_subplot(grid[1, 1])
    t0, t1 = float(traj.t[0]), float(traj.t[-1])
    norm, cmap = Normalize(t0, max(t1, t0 + 1e-9)), colormaps["viridis"]
    idx = np.unique(np.linspace(0, traj.t.shape[0] - 1, instants).round().astype(int))

    _draw_scene(ax_dv, sc)
    for n, i in enumerate(idx):
        _draw_body(ax_dv, _body(traj, i), sc.radius, cmap(norm(traj.t[i])), legend=n == 0)
    ax_dv.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    cax = ax_dv.inset_axes((1.03, 0.06, 0.24, 0.07))
    bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=cax, orientation="horizontal")
    bar.set_label("body drawn at t (s)", fontsize="small")

    for j in range(traj.points.shape[1]):
        ax_h.plot(traj.t, traj.points[:, j, 2], lw=1.2, label=f"point {j + 1}")
    ax_h.plot(traj.t, traj.dv[:, 2], "k-", lw=1.6, label="tool")
    if sc.h_star is not None:
        ax_h.axhline(sc.h_star, color="0.3", ls="--", lw=1.2, label=f"h* = {sc.h_star:.3g} m")
    ax_h.set(xlabel="t (s)", ylabel="h (m)", title="heights above the pipe surface")
    ax_h.grid(alpha=0.3)
    ax_h.legend(fontsize="small", ncol=2)

    _draw_section(ax_x, sc, [(i, cmap(norm(traj.t[i]))) for i in idx])
    failed = "" if traj.ok else f", {int(np.sum(~traj.success))} failed steps"
    fig.suptitle(
        f"dvqp trajectory ({traj.backend or 'unknown resolver'}): {traj.n_steps} steps, "
        f"{t1:.3g} s, R = {sc.radius:.3g} m{failed}"
    )
    fmt = target.suffix.lower()[1:]
    return _atomic(target, lambda tmp: fig.savefig(tmp, format=fmt, dpi=150))


def animate_trajectory(
    traj: Trajectory,
    path: str | Path,
    *,
    obstacles: Sequence[Obstacle] = (),
    orbital_level: float | None = None,
    weld_z: float | None = None,
    fps: int = 20,
    max_frames: int = 120,
) -> Path:
    """Save a GIF of the developed view with the body moving along the trajectory.

    Parameters
    ----------
    traj, obstacles, weld_z
        As in :func:`plot_trajectory`.
    path
        Output ``.gif``; its folder must exist.
    orbital_level
        ``h*`` (m), shown in the title if given.
    fps
        Frames per second, > 0.
    max_frames
        At most this many frames (samples are taken evenly, first and last included), >= 2.

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError, DvqpError
        As in :func:`plot_trajectory`.
    """
    target = output_path(path, (".gif",))
    sc = _scene(traj, obstacles, orbital_level, weld_z)
    if isinstance(fps, bool) or not isinstance(fps, Real) or not 0 < fps < math.inf:
        raise ParameterError("fps", f"must be > 0, got {fps!r}")
    _integer("max_frames", max_frames, 2)
    fig = _figure((9.5, float(np.clip(6.7 * sc.aspect + 1.2, 2.5, 9.0))))
    from matplotlib.animation import PillowWriter

    ax = fig.add_subplot()
    _draw_scene(ax, sc)
    artists = _draw_body(ax, _body(traj, 0), sc.radius, "tab:red")
    stamp = ax.text(0.01, 0.97, "", transform=ax.transAxes, va="top", fontsize="small")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    ax.set_title(ax.get_title() + ("" if sc.h_star is None else f", h* = {sc.h_star:.3g} m"))
    fig.canvas.draw()
    fig.set_layout_engine("none")  # freeze the layout: every frame has the same axes
    count = min(max_frames, traj.t.shape[0])
    frames = np.unique(np.linspace(0, traj.t.shape[0] - 1, count).round().astype(int))

    def write(tmp: str) -> None:
        writer = PillowWriter(fps=fps)
        with writer.saving(fig, tmp, dpi=100):
            for i in frames:
                for j, (lb, zb) in enumerate(_copies(_body(traj, i), sc.radius)):
                    artists[2 * j].set_data(lb, zb)
                    artists[2 * j + 1].set_data(lb[-1:], zb[-1:])
                stamp.set_text(f"t = {traj.t[i]:.2f} s")
                writer.grab_frame()

    return _atomic(target, write)


def _figure(size: tuple[float, float]) -> Figure:
    """A constrained-layout Figure on the Agg canvas (no pyplot, no display)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise DvqpError("plotting needs matplotlib: pip install 'dvqp[plot]'") from exc
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _atomic(target: Path, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``target``, then rename it to ``target``."""
    with atomic_file(target) as tmp:
        write(str(tmp))
    return target


def _integer(name: str, value: object, least: int) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise ParameterError(name, f"must be an integer >= {least}, got {value!r}")


class _Scene(NamedTuple):
    traj: Trajectory
    radius: float
    obstacles: tuple[Obstacle, ...]
    h_star: float | None
    weld: float | None
    limits: tuple[float, float, float, float]  # l_min, l_max, z_min, z_max of the DV axes, m

    @property
    def aspect(self) -> float:
        return (self.limits[3] - self.limits[2]) / (self.limits[1] - self.limits[0])


def _scene(
    traj: Trajectory, obstacles: Sequence[Obstacle], h_star: float | None, weld: float | None
) -> _Scene:
    """Check the inputs and fix the developed-view limits (z: everything drawn, padded)."""
    radius = float(traj.pipe_radius)
    if not 0 < radius < math.inf:
        raise ParameterError("pipe_radius", f"the trajectory has no valid pipe radius ({radius})")
    finite = np.all(np.isfinite(traj.points)) and np.all(np.isfinite(traj.dv))
    if traj.t.shape[0] < 1 or not finite:
        raise ParameterError("trajectory", "needs at least one sample and finite points")
    for name, value in (("orbital_level", h_star), ("weld_z", weld)):
        if value is not None and not (isinstance(value, Real) and math.isfinite(value)):
            raise ParameterError(name, f"must be a finite number, got {value!r}")
    z = [traj.points[..., 1].ravel(), traj.dv[:, 1]]
    z += [np.array([o.center[1] - o.radius, o.center[1] + o.radius]) for o in obstacles]
    zs = np.concatenate([*z, [] if weld is None else [float(weld)]])
    pad, edge = 0.08 * float(np.ptp(zs)) + 0.03, 1.12 * np.pi * radius
    limits = (-edge, edge, float(zs.min()) - pad, float(zs.max()) + pad)
    h = None if h_star is None else float(h_star)
    return _Scene(traj, radius, tuple(obstacles), h, None if weld is None else float(weld), limits)


def _wrap(l: NDArray[np.float64] | float, radius: float) -> NDArray[np.float64]:
    """Arc length wrapped into ``(−πR, πR]`` (atan2's interval), m."""
    return -wrap(-np.asarray(l, dtype=np.float64), radius)  # wrap() gives [−πR, πR)


def _body(traj: Trajectory, i: int) -> NDArray[np.float64]:
    """Body points then the tool at sample i, ``[l, z, h]``, l continuous along the body."""
    body = np.vstack([traj.points[i], traj.dv[i, :3]])
    body[:, 0] = unwrap(body[:, 0], 2.0 * np.pi * traj.pipe_radius)
    body[:, 0] += _wrap(body[0, 0], traj.pipe_radius) - body[0, 0]
    return body


def _copies(body: NDArray[np.float64], radius: float) -> list[tuple[NDArray, NDArray]]:
    """The body polyline (l, z) and its copies one period left and right (the axes clip)."""
    return [(body[:, 0] + s * 2.0 * np.pi * radius, body[:, 1]) for s in _SHIFTS]


def _draw_scene(ax: Axes, sc: _Scene) -> None:
    """Seam, shaded strips beyond it, weld, obstacles and the tool path in the (l, z) axes."""
    from matplotlib.patches import Circle

    traj, radius, weld = sc.traj, sc.radius, sc.weld
    half, period = np.pi * radius, 2.0 * np.pi * radius
    for side in (-1, 1):
        ax.axvspan(side * half, side * 2 * half, color="0.85", zorder=0)
        ax.axvline(side * half, color="0.4", lw=1.0, label="seam l = ±πR" if side < 0 else None)
    if weld is not None:
        ax.axhline(weld, color="tab:orange", ls="--", lw=1.5, label=f"weld z = {weld:.3g} m")
    for j, o in enumerate(sc.obstacles):
        cl = float(_wrap(o.center[0], radius))
        for s in _SHIFTS:
            style = {"fc": "tab:red", "ec": "darkred", "alpha": 0.3}
            label = "obstacle" if j == 0 and s == 0 else None
            ax.add_patch(Circle((cl + s * period, o.center[1]), o.radius, **style, label=label))
    lt = _wrap(traj.dv[:, 0], radius)
    jumps = np.flatnonzero(np.abs(np.diff(lt)) > half) + 1  # break the path at the seam
    lt, zt = np.insert(lt, jumps, np.nan), np.insert(traj.dv[:, 1], jumps, np.nan)
    for s in _SHIFTS:
        ax.plot(lt + s * period, zt, "k-", lw=1.0, zorder=3, label="tool path" if s == 0 else None)
    ax.set(xlim=sc.limits[:2], ylim=sc.limits[2:], aspect="equal")
    ax.set(xlabel="l, arc length around the pipe (m)", ylabel="z, along the pipe axis (m)")
    ax.set_title("developed view (pipe unrolled; shaded: beyond the seam)")


def _draw_body(
    ax: Axes, body: NDArray[np.float64], radius: float, color: Any, legend: bool = True
) -> list[Any]:
    """The body polyline (points, then tool ▲) and its copies: [line, tool marker] per copy."""
    artists = []
    for s, (lb, zb) in zip(_SHIFTS, _copies(body, radius), strict=True):
        label = "body (points 1..k, tool ▲)" if s == 0 and legend else None
        artists += ax.plot(lb, zb, "-o", color=color, lw=1.8, ms=3.5, label=label)
        artists += ax.plot(lb[-1:], zb[-1:], "^", color=color, ms=7)
    return artists


def _draw_section(ax: Axes, sc: _Scene, instants: Sequence[tuple[int, Any]]) -> None:
    """Pipe cross-section (x, y): wall, orbital circle, obstacle extents, body at (i, colour)."""
    traj, radius, h_star = sc.traj, sc.radius, sc.h_star
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    circle = np.array([np.cos(th), np.sin(th)])
    ax.plot(*(radius * circle), "k-", lw=1.5, label=f"pipe R = {radius:.3g} m")
    if h_star is not None:
        orbit = (radius + h_star) * circle
        ax.plot(*orbit, color="0.3", ls="--", lw=1.0, label="orbital level R + h*")
    for j, o in enumerate(sc.obstacles):
        arc = np.linspace(o.center[0] - o.radius, o.center[0] + o.radius, 50) / radius
        label = "obstacle (l extent)" if j == 0 else None
        xy = radius * np.cos(arc), radius * np.sin(arc)
        ax.plot(*xy, color="tab:red", lw=5, alpha=0.5, solid_capstyle="butt", label=label)
    for i, c in instants:
        body = np.vstack([traj.points[i], traj.dv[i, :3]])
        rho, angle = radius + body[:, 2], body[:, 0] / radius
        x, y = rho * np.cos(angle), rho * np.sin(angle)
        ax.plot(x, y, "-o", color=c, lw=1.5, ms=3)
        ax.plot(x[-1], y[-1], "^", color=c, ms=6)
    top = max(float(traj.points[..., 2].max()), float(traj.dv[:, 2].max()), h_star or 0.0, 0.0)
    reach = radius + top + 0.05 * radius
    ax.plot([-0.85 * radius, -reach], [0.0, 0.0], color="0.4", lw=1.0, label="seam (l = ±πR)")
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal")
    ax.set(xlabel="x (m)", ylabel="y (m)", title="cross-section (body coloured by time)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small", loc="center", framealpha=0.6)  # the pipe's inside is empty
