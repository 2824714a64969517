"""Drawing a trajectory: the developed view, the body, the pipe cross-section.

The helpers draw on given :class:`matplotlib.axes.Axes` and import matplotlib only when called.
In the developed view, l is shown wrapped into ``(−πR, πR]``; the strips just beyond the seam
``l = ±πR`` (shaded) repeat the other side of the pipe, so obstacles, the tool path and the body
stay continuous where they cross the seam.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Real
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from dvqp.errors import ParameterError
from dvqp.geometry.obstacle import ObstacleSet
from dvqp.kinematics.developed_view import unwrap, wrap

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from dvqp.geometry.shapes import Shape
    from dvqp.motion.trajectory import Trajectory

SHIFTS = (-1, 0, 1)
"""Copies of seam-periodic drawings, in periods ``2πR``."""


class View(NamedTuple):
    """A trajectory with what is drawn around it, checked by :func:`make_view`: the pipe
    ``radius``, orbital level ``h_star``, ``weld`` z and the body's ``min_height`` (None: not
    drawn), and the developed-view axes' ``limits`` ``(l_min, l_max, z_min, z_max)``, all in
    m."""

    traj: Trajectory
    radius: float
    obstacles: tuple[Shape, ...]
    h_star: float | None
    weld: float | None
    limits: tuple[float, float, float, float]
    min_height: float | None = None
    labels: tuple[str, ...] = ()
    """What reports call each obstacle (its name, else ``obstacles[j]``)."""

    @property
    def aspect(self) -> float:
        """Height over width of the developed-view axes."""
        return (self.limits[3] - self.limits[2]) / (self.limits[1] - self.limits[0])


def make_view(
    traj: Trajectory,
    obstacles: Sequence[Shape] = (),
    orbital_level: float | None = None,
    weld_z: float | None = None,
    min_height: float | None = None,
    full: bool = False,
) -> View:
    """Check the inputs and fix the developed-view limits: z spans everything drawn, l the
    arc where the arm (rail point, body, tool; over the whole run) and the obstacles are, both
    padded (:func:`arc_extent`), or with ``full`` (or where that arc is most of the pipe) the
    whole circumference and a strip beyond each side of the seam.

    Raises
    ------
    ParameterError
        No valid pipe radius, no sample or non-finite points, a non-finite level or weld.
    """
    radius = float(traj.pipe_radius)
    if not 0 < radius < math.inf:
        raise ParameterError("pipe_radius", f"the trajectory has no valid pipe radius ({radius})")
    finite = np.all(np.isfinite(traj.points)) and np.all(np.isfinite(traj.tool))
    if traj.t.shape[0] < 1 or not finite:
        raise ParameterError("trajectory", "needs at least one sample and finite points")
    for name, value in (
        ("orbital_level", orbital_level),
        ("weld_z", weld_z),
        ("min_height", min_height),
    ):
        if value is not None and not (isinstance(value, Real) and math.isfinite(value)):
            raise ParameterError(name, f"must be a finite number, got {value!r}")
    h = None if orbital_level is None else float(orbital_level)
    weld = None if weld_z is None else float(weld_z)
    z = [
        traj.points[..., 1].ravel(),
        traj.tool[:, 1],
        traj.rail[:, 1],  # rail: () if none
        *(np.array(o.z_range) for o in obstacles),
    ]
    zs = np.concatenate([*z, [] if weld is None else [weld]])
    pad, edge = 0.08 * float(np.ptp(zs)) + 0.03, 1.12 * np.pi * radius  # l: beyond the seams
    arc = None if full else arc_extent(traj, obstacles, radius)
    lo, hi = (-edge, edge) if arc is None else arc
    limits = (lo, hi, float(zs.min()) - pad, float(zs.max()) + pad)
    floor = None if min_height is None else float(min_height)
    labels = ObstacleSet.of(obstacles).labels
    return View(traj, radius, tuple(obstacles), h, weld, limits, floor, labels)


def arc_extent(
    traj: Trajectory, obstacles: Sequence[Shape], radius: float
) -> tuple[float, float] | None:
    """The shortest arc ``(l_lo, l_hi)`` (m) that holds every sample's arm (its rail point,
    body points and tool) and every obstacle's outline but bands, padded by 8 % of its length
    and 3 cm a side, its middle wrapped into ``(−πR, πR]`` (``l_hi`` may pass the seam); None
    if it would be 2πR or more. l is periodic: the arc is the circumference less the longest
    stretch that nothing occupies."""
    period = 2.0 * np.pi * radius
    recorded = traj.rail.shape[0] == traj.t.shape[0]
    rail = traj.rail[:, :1] if recorded else np.zeros((traj.t.shape[0], 0))
    arm = unwrap(np.hstack([rail, traj.points[..., 0], traj.tool[:, :1]]), period, axis=1)
    rings = [o.outline()[:, 0] for o in obstacles]
    rings = [r for r in rings if not np.isnan(r).all()]  # a band occupies every l
    lo = np.concatenate([arm.min(axis=1), [r.min() for r in rings]])
    width = np.concatenate([np.ptp(arm, axis=1), [np.ptp(r) for r in rings]])
    order = np.argsort(lo % period)
    start, reach = (lo % period)[order], np.maximum.accumulate((lo % period + width)[order])
    wrapped = reach[-1] - period  # what passes 2πR covers the first stretches again
    gaps = np.append(start[1:] - np.maximum(reach[:-1], wrapped), start[0] - wrapped)
    g = int(np.argmax(gaps))  # the longest empty stretch: after reach[g]
    first = start[(g + 1) % start.shape[0]]
    length = period - float(gaps[g])
    margin = 0.08 * length + 0.03
    if length + 2.0 * margin >= period:
        return None
    middle = first + 0.5 * length
    shift = float(wrap_arc(middle, radius)) - middle
    return first + shift - margin, first + shift + length + margin


def wrap_arc(l: NDArray[np.float64] | float, radius: float) -> NDArray[np.float64]:
    """Arc length wrapped into ``(−πR, πR]`` (atan2's interval), m."""
    return -wrap(-np.asarray(l, dtype=np.float64), radius)  # wrap() gives [−πR, πR)


def body_at(traj: Trajectory, i: int) -> NDArray[np.float64]:
    """The rail point (if recorded: the carriage link is then drawn too), the body points and
    the tool at sample i, shape (k+1, 3) or (k+2, 3), ``[l, z, h]`` (m); l is continuous along
    the body and starts in ``(−πR, πR]``."""
    rail = traj.rail[i : i + 1] if traj.rail.shape[0] == traj.t.shape[0] else np.zeros((0, 3))
    body = np.vstack([rail, traj.points[i], traj.tool[i, :3]])
    body[:, 0] = unwrap(body[:, 0], 2.0 * np.pi * traj.pipe_radius)
    body[:, 0] += wrap_arc(body[0, 0], traj.pipe_radius) - body[0, 0]
    return body


def body_copies(body: NDArray[np.float64], radius: float) -> list[tuple[NDArray, NDArray]]:
    """The body polyline (l, z) and its copies one period left and right (the axes clip)."""
    return [(body[:, 0] + s * 2.0 * np.pi * radius, body[:, 1]) for s in SHIFTS]


def draw_developed_view(ax: Axes, view: View) -> None:
    """Seam, shaded strips beyond it, weld, obstacles and the tool path in the (l, z) axes."""
    half, weld = np.pi * view.radius, view.weld
    for side in (-1, 1):
        ax.axvspan(side * half, side * 2 * half, color="0.85", zorder=0)
        ax.axvline(side * half, color="0.4", lw=1.0, label="seam l = ±πR" if side < 0 else None)
    if weld is not None:
        ax.axhline(weld, color="tab:orange", ls="--", lw=1.5, label=f"weld z = {weld:.3g} m")
    _draw_obstacles(ax, view)
    _draw_tool_path(ax, view)
    ax.set(xlim=view.limits[:2], ylim=view.limits[2:], aspect="equal")
    ax.set(xlabel="l, arc length around the pipe (m)", ylabel="z, along the pipe axis (m)")
    ax.set_title("developed view (pipe unrolled; shaded: beyond the seam)")


def _draw_obstacles(ax: Axes, view: View) -> None:
    """Every obstacle's outline, wrapped, with its copies one period left and right; a band
    as a strip across the whole view. Each is labelled as reports name it, with its height
    if it has one (one without stands to the sky); an obstacle with a height is hatched."""
    from matplotlib.patches import Polygon as Patch

    period = 2.0 * np.pi * view.radius
    style = {"fc": "tab:red", "ec": "darkred", "alpha": 0.3}
    shown: set[bool] = set()
    for j, o in enumerate(view.obstacles):
        ring, bounded = o.outline(), o.bounded
        kind = "obstacle with a height" if bounded else "obstacle (unbounded)"
        label = None if bounded in shown else kind
        shown.add(bounded)
        look = {**style, "hatch": "//" if bounded else None}
        if np.isnan(ring[:, 0]).all():  # a band: every l
            ax.axhspan(ring[0, 1], ring[1, 1], **look, label=label)
            at = (view.limits[0] + 0.02 * (view.limits[1] - view.limits[0]), ring[:, 1].mean())
        else:
            ref = float(np.mean(ring[:, 0]))
            shift = float(wrap_arc(ref, view.radius)) - ref
            for s in SHIFTS:
                moved = ring + np.array([shift + s * period, 0.0])
                ax.add_patch(Patch(moved, closed=True, **look, label=label if s == 0 else None))
            at = (ref + shift, float(np.mean(ring[:, 1])))
        ax.annotate(
            obstacle_caption(view.labels[j] if view.labels else f"obstacles[{j}]", o),
            at,
            ha="left" if np.isnan(ring[:, 0]).all() else "center",
            va="center",
            fontsize="x-small",
            color="darkred",
            zorder=4,
            annotation_clip=True,
        )


def obstacle_caption(label: str, shape: Shape) -> str:
    """An obstacle's caption in pictures: what reports call it, and its height if it has one
    (``"support, 25 mm high"``)."""
    return f"{label}, {shape.height * 1e3:.3g} mm high" if shape.bounded else label


def _draw_tool_path(ax: Axes, view: View) -> None:
    """The tool path, wrapped and broken where it crosses the seam, and its copies."""
    traj, half = view.traj, np.pi * view.radius
    lt = wrap_arc(traj.tool[:, 0], view.radius)
    jumps = np.flatnonzero(np.abs(np.diff(lt)) > half) + 1
    lt, zt = np.insert(lt, jumps, np.nan), np.insert(traj.tool[:, 1], jumps, np.nan)
    for s in SHIFTS:
        label = "tool path" if s == 0 else None
        ax.plot(lt + s * 2.0 * half, zt, "k-", lw=1.0, zorder=3, label=label)


def draw_body(
    ax: Axes,
    body: NDArray[np.float64],
    radius: float,
    color: Any,
    legend: bool = True,
    rail: bool = False,
) -> list[Any]:
    """The body polyline (the rail point first if ``rail``, points, then tool ▲) and its
    copies, in ``color``; the middle copy labelled for the legend if ``legend``.

    ``body`` is :func:`body_at`'s, ``radius`` the pipe's (m). Returns ``[line, tool marker]``
    per copy, in :data:`SHIFTS` order.
    """
    artists, parts = [], "rail, " if rail else ""
    for s, (lb, zb) in zip(SHIFTS, body_copies(body, radius), strict=True):
        label = f"body ({parts}points 1..k, tool ▲)" if s == 0 and legend else None
        artists += ax.plot(lb, zb, "-o", color=color, lw=1.8, ms=3.5, label=label)
        artists += ax.plot(lb[-1:], zb[-1:], "^", color=color, ms=7)
    return artists


def draw_section(ax: Axes, view: View, instants: Sequence[tuple[int, Any]]) -> None:
    """Pipe cross-section (x, y): wall, orbital circle, obstacle extents, and the body at the
    ``(sample index, colour)`` pairs of ``instants``."""
    radius, h_star = view.radius, view.h_star
    th = np.linspace(0.0, 2.0 * np.pi, 361)
    circle = np.array([np.cos(th), np.sin(th)])
    ax.plot(*(radius * circle), "k-", lw=1.5, label=f"pipe R = {radius:.3g} m")
    if h_star is not None:
        orbit = (radius + h_star) * circle
        ax.plot(*orbit, color="0.3", ls="--", lw=1.0, label="orbital level R + h*")
    shown: set[bool] = set()
    for o in view.obstacles:
        ring = o.outline()
        if np.isnan(ring[:, 0]).all():  # a band covers the whole circumference
            lo, hi = -np.pi * radius, np.pi * radius
        else:
            lo, hi = float(ring[:, 0].min()), float(ring[:, 0].max())
        arc = np.linspace(lo, hi, 90) / radius
        label = None if o.bounded in shown else "obstacle (l extent)"
        shown.add(o.bounded)
        if o.bounded:  # drawn at its height: the sector from the surface up to it
            label = label and "obstacle (l extent, to its height)"
            outer = radius + o.height
            x = np.concatenate([radius * np.cos(arc), outer * np.cos(arc[::-1])])
            y = np.concatenate([radius * np.sin(arc), outer * np.sin(arc[::-1])])
            ax.fill(x, y, fc="tab:red", ec="darkred", alpha=0.35, hatch="//", label=label)
            continue
        xy = radius * np.cos(arc), radius * np.sin(arc)
        ax.plot(*xy, color="tab:red", lw=5, alpha=0.5, solid_capstyle="butt", label=label)
    for i, color in instants:  # the body at sample i (from the rail point), tool ▲ at its end
        body = body_at(view.traj, i)
        rho, angle = radius + body[:, 2], body[:, 0] / radius
        x, y = rho * np.cos(angle), rho * np.sin(angle)
        ax.plot(x, y, "-o", color=color, lw=1.5, ms=3)
        ax.plot(x[-1], y[-1], "^", color=color, ms=6)
    _finish_section(ax, view)


def _finish_section(ax: Axes, view: View) -> None:
    """The seam mark, square limits around everything drawn, labels and legend."""
    traj, radius = view.traj, view.radius
    top = max(
        float(traj.points[..., 2].max()), float(traj.tool[:, 2].max()), view.h_star or 0.0, 0.0
    )
    reach = radius + top + 0.05 * radius
    ax.plot([-0.85 * radius, -reach], [0.0, 0.0], color="0.4", lw=1.0, label="seam (l = ±πR)")
    ax.set(xlim=(-reach, reach), ylim=(-reach, reach), aspect="equal")
    ax.set(xlabel="x (m)", ylabel="y (m)", title="cross-section (body coloured by time)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="x-small", loc="center", framealpha=0.6)  # the pipe's inside is empty
