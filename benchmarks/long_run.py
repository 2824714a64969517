"""A 10 000-step JOG with DAQP, recording included: wall time once compiled, and memory.

Usage::

    python benchmarks/long_run.py [--steps 10000] [--backend daqp] [--repeat 3]

The scene is ``scenes/paper-two-inlets.toml`` with its JOG replaced by a back-and-forth along
the weld (±5 cm/s, 1 s each way) long enough for ``--steps`` steps of 5 ms. A first run pays
compiling (or loading the compiled code from the cache); the next ``--repeat`` runs are timed
(``dvqp.plan`` as a whole: set-up, every step, the trajectory). Memory is traced with
``tracemalloc`` during one run: the memory in use at a quarter and at three quarters of the
steps (everything is preallocated: it must not grow per step), and the peak, which includes
the recorder's arrays and the trajectory built from them at the end.
"""

from __future__ import annotations

import argparse
import re
import time
import tracemalloc

import numpy as np
from checkout import ROOT  # before dvqp: this checkout's, not an installed one

import dvqp


def scene_with(steps: int) -> dvqp.Scene:
    """The paper scene with a back-and-forth JOG of ``steps`` steps of 5 ms."""
    text = (ROOT / "scenes" / "paper-two-inlets.toml").read_text(encoding="utf-8")
    head = re.split(r"\n\[\[motion\.jog\]\]", text)[0]
    seconds = steps * 0.005
    legs = []
    for i in range(int(np.ceil(seconds))):
        sign = 1.0 if i % 2 == 0 else -1.0
        duration = min(1.0, seconds - i)
        legs.append(
            f"\n[[motion.jog]]\nduration = {duration}\nvelocity = [{0.05 * sign}, 0.0, 0.0, 0.0]\n"
        )
    return dvqp.scenes.loads(head + "".join(legs), f"long-{steps}.toml")


def traced(scene: dvqp.Scene, backend: str) -> tuple[int, int, int, int]:
    """Memory in use (bytes) at 1/4 and 3/4 of the steps, the peak, and the trajectory's
    array bytes."""
    marks: dict[int, int] = {}

    def progress(k: int, n: int) -> None:
        if k in (n // 4, 3 * n // 4):
            marks[k] = tracemalloc.get_traced_memory()[0]

    tracemalloc.start()
    traj = dvqp.plan(scene, backend, progress=progress)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    arrays = sum(v.nbytes for v in vars(traj).values() if isinstance(v, np.ndarray))
    quarter, three = (marks[k] for k in sorted(marks))
    return quarter, three, peak, arrays


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=10_000)
    parser.add_argument("--backend", default="daqp")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    scene = scene_with(args.steps)
    started = time.perf_counter()
    first = dvqp.plan(scene, args.backend)
    print(
        f"first run (compiles or loads the cache): {time.perf_counter() - started:.3f} s, "
        f"{first.n_steps} steps"
    )
    times = []
    for _ in range(args.repeat):
        started = time.perf_counter()
        traj = dvqp.plan(scene, args.backend)
        times.append(time.perf_counter() - started)
    print(
        f"{traj.n_steps} steps with {args.backend}: median {np.median(times):.3f} s "
        f"({np.median(times) / traj.n_steps * 1e6:.1f} us/step) over {args.repeat} runs; "
        f"failed steps {int((~traj.success).sum())}"
    )
    quarter, three, peak, arrays = traced(scene, args.backend)
    growth = (three - quarter) / (traj.n_steps // 2)
    print(
        f"memory in use: {quarter / 1e6:.2f} MB at 1/4 of the steps, {three / 1e6:.2f} MB at "
        f"3/4 ({growth:.1f} bytes per step); peak {peak / 1e6:.2f} MB, the trajectory's "
        f"arrays {arrays / 1e6:.2f} MB"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
