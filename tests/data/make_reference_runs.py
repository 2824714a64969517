"""Write ``reference_runs.npz``: every bundled scene on the exact backends, as a regression record.

First written at commit 4a597ea, before the step was composed from task, term and limit
objects (the composed step reproduced it bit for bit). Rewritten once, on purpose, when the
probe and its holder became guarded parts (``min_clearance`` covers them) and the dampers began
to pull a drift below their safe value back (QP runs moved by at most 2e-4 rad; the baseline
did not move). Rewritten again when runs began to end at rest: each run gained its braking
steps (one, two on weld-circumference's QP runs, five on joint-limit's), the samples before
them bit for bit those of the code before (the file then stored differed from them by up to
2.1e-12 rad/s, from the code of its own time). Rewritten when the link chords' lowest points
joined the height floor: joint-limit's and narrow-passage's QP runs hold a chord at
``min_height`` and moved by up to 0.099 and 0.068 rad; every other run is as it was.
Rewritten when the links' clearances became those of their real DV images (the straight 3-D
link mapped to the DV, not the straight DV segment): the baselines' joint paths are bit for bit
the same, their recorded clearances moved by up to 1.0 mm (weld-circumference); the QP runs
that hold a link at its margin (many-obstacles, narrow-passage, paper-two-inlets) moved by up to
0.0036 rad. Rewritten again when those clearances came from a branch and bound over the link's
pieces (to the same 10 µm): recorded clearances moved by up to 7.7 µm, QP runs by up to
0.0011 rad (pipe-rack). Rewritten when the inlets' distances became those of their exact
curve (no longer a 256-vertex polygon, whose chords lay up to 5.6 µm inside it): only the two
inlet scenes moved. Their QP runs' recorded clearances moved by at most 5.9 µm
(paper-inlets; pipe-rack 4.5 µm), their joints by at most 7.5e-5 rad; pipe-rack's baseline
by 4.5 µm of clearance and not at all in its joints. paper-inlets' baseline (pinv, which
runs into an inlet and breaks the margin) is bit for bit the same until sample 510, where a
point enters the inlet and the discontinuous repulsion (``∇e = 2ρ n`` at the outline) starts
from the exact curve's normal instead of a polygon vertex's (6e-4 rad apart): from there its
joints moved by up to 0.036 rad and its clearance by up to 3.7 mm (lowest −3.7 mm before,
−0.9 mm now).
Rewritten when the halving of a link into pieces began at the pieces (of the same halving's
grid) round the straight link's closest point instead of at the whole link: another set of
pieces, to the same 10 µm. The baselines' joint paths are bit for bit the same, their
recorded clearances moved by up to 5.7 µm (weld-circumference); the QP runs that hold a link
at its margin moved by up to 1.7e-4 rad (narrow-passage; many-obstacles 1.7e-4; paper-two-inlets
not at all) and their clearances by up to 7.7 µm; every status is the same.
``tests/run/test_reference_runs.py`` checks that today's code reproduces it within 1e-9. Run
``python tests/data/make_reference_runs.py`` only when a change of results is intended, and say
why in the commit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from dvqp import load_scene, plan

HERE = Path(__file__).resolve().parent
SCENES = HERE.parent.parent / "scenes"
BACKENDS = ("pinv", "daqp", "quadprog")
FIELDS = ("q", "qdot", "w", "min_clearance", "task_error")


def main() -> None:
    out: dict[str, np.ndarray] = {}
    for path in sorted(SCENES.glob("*.toml")):
        scene = load_scene(path)
        for backend in BACKENDS:
            traj = plan(scene, backend)
            for name in FIELDS:
                out[f"{path.stem}/{backend}/{name}"] = getattr(traj, name)
            out[f"{path.stem}/{backend}/status"] = np.asarray(traj.status, dtype=str)
    np.savez_compressed(HERE / "reference_runs.npz", **out)


if __name__ == "__main__":
    main()
