"""How ``dvqp bench`` scales: serial, a local process pool and a Dask LocalCluster.

Usage::

    python benchmarks/bench_scaling.py [--repeats 3] [--count 48] [--seed 11]
                                       [--backends pinv,daqp,osqp] [--workers 2]

Runs ``dvqp bench`` (the command line, each in a fresh process, as a user does) serially,
with ``--workers W`` and with ``--scheduler local --workers W``, once unmeasured to warm
numba's cache, then ``--repeats`` rounds, each running the three in a rotated order
(interleaved, so that a machine shared with other work slows them alike). Prints each run's
wall time and CPU time (user + sys of the process and its children, s), then per
configuration the median wall time, the median of its per-round ratios to serial (the robust
figure on a noisy machine), the ratio of the medians, and the workers' start-up the command
printed (``worker start-up … s``). Checks that every configuration gave the outcomes of the
serial run (``dvqp.bench.outcome_differences``, to the last bit).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from checkout import ROOT  # before dvqp: this checkout's, not an installed one

from dvqp.bench import outcome_differences

STARTUP = re.compile(r"worker start-up ([0-9., ]+) s")


def configurations(workers: int) -> dict[str, list[str]]:
    """The three ways to run the suite, by name: extra ``dvqp bench`` arguments."""
    return {
        "serial": [],
        f"--workers {workers}": ["--workers", str(workers)],
        f"--scheduler local --workers {workers}": [
            "--scheduler",
            "local",
            "--workers",
            str(workers),
        ],
    }


def run(command: list[str], out: Path) -> dict[str, object]:
    """One ``dvqp bench``: wall and CPU time (s), the start-ups it printed, its results."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [*command, "--json", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        check=False,
    )
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(command)}: exit {done.returncode}: {done.stderr[-500:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    found = STARTUP.search(done.stdout)
    startup = [float(s) for s in found.group(1).split(",")] if found else []
    results = json.loads(out.read_text())["results"]
    return {"wall": wall, "cpu": cpu, "startup": startup, "results": results}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--count", type=int, default=48)
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--backends", default="pinv,daqp,osqp")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    base = [
        sys.executable,
        "-m",
        "dvqp",
        "bench",
        "--count",
        str(args.count),
        "--seed",
        str(args.seed),
        "--backends",
        args.backends,
    ]
    configs = configurations(args.workers)
    names = list(configs)
    print(f"cpus {os.cpu_count()}, load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    runs: dict[str, list[dict[str, object]]] = {name: [] for name in names}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "bench.json"
        run(base, out)  # numba's cache warm for every path the suite takes, unmeasured
        for repeat in range(args.repeats):
            order = names[repeat % len(names) :] + names[: repeat % len(names)]
            for name in order:
                result = run(base + configs[name], out)
                runs[name].append(result)
                print(
                    f"round {repeat + 1}  {name:<36} wall {result['wall']:6.2f} s  "
                    f"cpu {result['cpu']:6.2f} s  start-up {result['startup']}"
                )
    serial = [r["wall"] for r in runs["serial"]]
    print(
        f"\n{'configuration':<36} {'median s':>9} {'x serial':>9} {'x (medians)':>12}  "
        "start-up per worker s (median)  outcomes"
    )
    for name in names:
        walls = [r["wall"] for r in runs[name]]
        ratios = [s / w for s, w in zip(serial, walls, strict=True)]
        starts = [r["startup"] for r in runs[name] if r["startup"]]
        per_worker = [statistics.median(s) for s in zip(*starts, strict=False)] if starts else []
        same = all(
            not outcome_differences(runs["serial"][0]["results"], r["results"], tol=0.0)
            for r in runs[name]
        )
        print(
            f"{name:<36} {statistics.median(walls):9.2f} {statistics.median(ratios):9.2f} "
            f"{statistics.median(serial) / statistics.median(walls):12.2f}  "
            f"{', '.join(f'{s:.2f}' for s in per_worker) or '-':<31} "
            f"{'same as serial' if same else 'DIFFER'}"
        )
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
