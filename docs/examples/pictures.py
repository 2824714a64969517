"""Draw the pictures of the README and of docs/cli.md from the paper's scene.

Run from the repository's root: ``python docs/examples/pictures.py``. It plans
``scenes/paper-two-inlets.toml`` with DAQP and with the pseudoinverse baseline, and writes
into ``docs/img/``: each run's figure (``paper-two-inlets.png``, ``paper-two-inlets-pinv.png``,
what ``dvqp plot`` draws) and the baseline's limits page (``paper-two-inlets-limits.png``,
what ``dvqp plot --limits`` draws), where its clearance to the lower inlet and its joint
accelerations cross their bounds.
"""

from __future__ import annotations

from pathlib import Path

import dvqp
from dvqp.cli.limit_series import limit_series
from dvqp.cli.plot import plot_trajectory
from dvqp.cli.plot_limits import plot_limits
from dvqp.scenes import environment

IMG = Path("docs/img")


def main() -> None:
    scene = dvqp.load_scene("scenes/paper-two-inlets.toml")
    env = environment(scene.text)
    drawn = {"obstacles": env.obstacles, "orbital_level": env.orbital_level, "weld_z": env.weld,
             "min_height": env.min_height}  # fmt: skip
    for backend, name in (("daqp", "paper-two-inlets"), ("pinv", "paper-two-inlets-pinv")):
        traj = dvqp.plan(scene, backend)
        print(plot_trajectory(traj, IMG / f"{name}.png", **drawn))
    title = f"{scene.name} / pinv (the paper's baseline): limits over time"
    print(plot_limits(limit_series(scene, traj), IMG / "paper-two-inlets-limits.png", title))


if __name__ == "__main__":
    main()
