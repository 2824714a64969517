"""``dvqp plot --3d``: a still of the 3-D view (matplotlib's mplot3d, no browser).

It draws the same geometry as ``dvqp view`` (:func:`dvqp.view.scene3d.scene_3d`): the pipe and
the obstacles shaded, the rail, weld and path on the side facing the camera, the arm at its
first sample (faint) and its last (links at their margin red), looked at from outside the
pipe, square on to the arm.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from dvqp.cli.figures import new_figure, save_figure
from dvqp.view.scene3d import COLORS, Scene3D

LIGHT = np.array([0.4, -0.3, 0.87])
"""Direction of the light for the shading (unit vector)."""


def plot_3d(view: Scene3D, target: Path, dpi: int = 130) -> Path:
    """Draw ``view`` and save it to ``target`` (``.png``, ``.svg`` or ``.pdf``; returned)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    fig = new_figure((8.0, 6.0))
    ax = fig.add_subplot(projection="3d", computed_zorder=False)
    azim = _facing(view)
    triangles, colors = _shaded(view)
    ax.add_collection3d(Poly3DCollection(triangles, facecolors=colors, edgecolors="none", zorder=1))
    toward = np.array([math.cos(azim), math.sin(azim)])
    for line in view.lines:
        pts = line.points.copy()
        pts[pts[:, :2] @ toward < 0.0] = np.nan  # the far side, hidden by the pipe
        ax.plot(*pts.T, color=_rgb(line.color), lw=2.0, zorder=3, label=line.name)
    _arm(ax, view, 0, alpha=0.35)
    _arm(ax, view, len(view.t) - 1, alpha=1.0)
    _frame(ax, view, azim)
    ax.set_title(view.title, fontsize=10)
    ax.plot([], [], color=_rgb(COLORS["arm"]), lw=5.0, label="arm (first sample faint)")
    ax.plot([], [], color=_rgb(COLORS["margin"]), lw=5.0, label="link at its margin")
    ax.legend(loc="upper left", fontsize=8, facecolor="0.82")
    return save_figure(fig, target, dpi)


def _facing(view: Scene3D) -> float:
    """The azimuth (rad) of the arm's mean direction round the pipe axis."""
    xy = view.chain[..., :2].reshape(-1, 2)
    return math.atan2(float(xy[:, 1].sum()), float(xy[:, 0].sum()))


def _shaded(view: Scene3D) -> tuple[np.ndarray, np.ndarray]:
    """Every mesh's triangles (T, 3, 3) and their shaded colours (T, 3), in one collection
    so that mplot3d sorts them by depth together."""
    tris, colors = [], []
    for mesh in view.meshes:
        t = mesh.vertices[mesh.faces]
        normal = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-15)
        light = 0.55 + 0.45 * np.abs(normal @ LIGHT)
        tris.append(t)
        colors.append(np.clip(light[:, None] * _rgb(mesh.color), 0.0, 1.0))
    return np.concatenate(tris), np.concatenate(colors)


def _arm(ax, view: Scene3D, n: int, alpha: float) -> None:  # type: ignore[no-untyped-def]
    """The arm at sample ``n``: its links (red at their margin) and joints."""
    chain = view.chain[n]
    for i in range(len(chain) - 1):
        color = COLORS["margin"] if view.at_margin[n, i] else COLORS["arm"]
        ax.plot(
            *chain[i : i + 2].T,
            color=_rgb(color),
            lw=5.0,
            alpha=alpha,
            zorder=4,
            solid_capstyle="round",
        )
    ax.scatter(*chain.T, color="k", s=10, alpha=alpha, zorder=5, depthshade=False)


def _frame(ax, view: Scene3D, azim: float) -> None:  # type: ignore[no-untyped-def]
    """Equal scales round the pipe and the arm, looked at from outside, square on (no axes:
    the pipe's radius gives the scale)."""
    pts = np.concatenate([m.vertices for m in view.meshes] + [view.chain.reshape(-1, 3)])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]))
    ax.set_box_aspect(tuple(hi - lo), zoom=1.25)
    ax.view_init(elev=15.0, azim=math.degrees(azim), roll=0.0)
    ax.set_axis_off()


def _rgb(color: tuple[int, int, int]) -> np.ndarray:
    return np.asarray(color, dtype=np.float64) / 255.0
