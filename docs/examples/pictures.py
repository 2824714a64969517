"""Draw the pictures of the README, docs/cli.md and docs/paper.md.

Run from the repository's root: ``python docs/examples/pictures.py``. It plans
``scenes/paper-two-inlets.toml`` with DAQP and with the pseudoinverse baseline, and writes
into ``docs/img/``: each run's figure (``paper-two-inlets.png``, ``paper-two-inlets-pinv.png``,
what ``dvqp plot`` draws) and the baseline's limits page (``paper-two-inlets-limits.png``,
what ``dvqp plot --limits`` draws), where its clearance to the lower inlet and its joint
accelerations cross their bounds. It also plans ``scenes/reconfiguration.toml`` (the paper's
Figs. 8 -> 9) with both and writes ``reconfiguration.png`` and ``reconfiguration-pinv.png``,
and the still of the 3-D view of the baseline's run of the paper's scene
(``paper-two-inlets-3d.png``, what ``dvqp plot --3d`` draws).
"""

from __future__ import annotations

from pathlib import Path

import dvqp
from dvqp.cli.limit_series import limit_series
from dvqp.cli.plot import plot_trajectory
from dvqp.cli.plot3d import plot_3d
from dvqp.cli.plot_limits import plot_limits
from dvqp.scenes import environment
from dvqp.view.scene3d import scene_3d

IMG = Path("docs/img")


def draw_runs(scene: dvqp.Scene) -> dvqp.Trajectory:
    """Plan ``scene`` with DAQP and with pinv, draw each run; return the baseline's run."""
    env = environment(scene.text)
    drawn = {
        "obstacles": env.obstacles,
        "orbital_level": env.orbital_level,
        "weld_z": env.weld,
        "min_height": env.min_height,
    }
    for backend, name in (("daqp", scene.name), ("pinv", f"{scene.name}-pinv")):
        traj = dvqp.plan(scene, backend)
        print(plot_trajectory(traj, IMG / f"{name}.png", **drawn))
    return traj


def main() -> None:
    draw_runs(dvqp.load_scene("scenes/reconfiguration.toml"))
    scene = dvqp.load_scene("scenes/paper-two-inlets.toml")
    traj = draw_runs(scene)
    title = f"{scene.name} / pinv (the paper's baseline): limits over time"
    print(plot_limits(limit_series(scene, traj), IMG / "paper-two-inlets-limits.png", title))
    view = scene_3d(scene, traj.q, traj.t, f"{scene.name} / pinv (the paper's baseline)")
    print(plot_3d(view, IMG / "paper-two-inlets-3d.png"))


if __name__ == "__main__":
    main()
