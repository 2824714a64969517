"""Start-up cost: what compiles when, and the CPU of a first and a cached run.

Usage::

    python benchmarks/startup.py [SCENE] [--backend daqp]

Every measurement is a fresh Python process. "cold" points numba's cache (``NUMBA_CACHE_DIR``)
at an empty temporary directory, as after installing dvqp: whatever a command needs compiles;
the following commands share that directory, so what was compiled before is loaded. For each
command it prints the wall time, the CPU time of the process (user + sys) and how many numba
functions were compiled (not loaded from the cache) in it.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROBE = """
import json, sys
from numba.core import event

compiled = []

class Count(event.Listener):
    def on_start(self, ev):
        compiled.append(1)

    def on_end(self, ev):
        pass

event.register("numba:compile", Count())
args = sys.argv[1:]
if args[0] == "import":
    import dvqp  # noqa: F401
    code = 0
else:
    from dvqp.cli import main

    code = main(args)
print(json.dumps({"compiled": len(compiled), "code": code}), file=sys.stderr)
"""


def measure(args: list[str], env: dict[str, str]) -> dict[str, float]:
    """Wall time, CPU (user + sys, s) and compiled functions of ``dvqp <args>`` in a fresh
    process (``import`` for ``import dvqp`` alone)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-c", PROBE, *args],
        env=env,
        capture_output=True,
        text=True,
        check=False,
        cwd=ROOT,
    )
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    found = json.loads(out.stderr.strip().splitlines()[-1])
    return {"wall": wall, "cpu": cpu, **found}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default="scenes/paper-two-inlets.toml")
    parser.add_argument("--backend", default="daqp")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        trajectory = str(Path(tmp) / "run.npz")
        runs = [
            ("cold: import dvqp", ["import"]),
            ("cold: dvqp --help", ["--help"]),
            ("cold: dvqp backends", ["backends"]),
            (
                f"cold: dvqp plan ({args.backend})",
                ["plan", args.scene, "--backend", args.backend, "-o", trajectory],
            ),
            ("then: dvqp plot", ["plot", trajectory, "-o", str(Path(tmp) / "run.png")]),
            ("cached: dvqp plan", ["plan", args.scene, "--backend", args.backend]),
            ("then: dvqp compare (every backend)", ["compare", args.scene]),
        ]
        env = {**os.environ, "NUMBA_CACHE_DIR": str(Path(tmp) / "numba"), "MPLBACKEND": "Agg"}
        rows = [(label, measure(command, env)) for label, command in runs]
        env["NUMBA_CACHE_DIR"] = str(Path(tmp) / "numba-readme")
        rows.append(
            ("cold: dvqp compare (README's first command)", measure(["compare", args.scene], env))
        )
    print(f"{'command':<45} {'wall s':>7} {'cpu s':>7} {'compiled':>9} {'exit':>5}")
    for label, m in rows:
        print(f"{label:<45} {m['wall']:7.2f} {m['cpu']:7.2f} {m['compiled']:9.0f} {m['code']:5.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
