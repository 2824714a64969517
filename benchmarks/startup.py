"""Start-up cost as a fresh clone meets it: what compiles when, and the CPU of first runs.

Usage::

    python benchmarks/startup.py [SCENE] [--backend daqp]

Every measurement is a fresh Python process with empty caches: ``NUMBA_CACHE_DIR``, ``HOME`` and
``XDG_CACHE_HOME`` point at new empty temporary folders, as on a machine that has just
installed dvqp (whatever a command needs compiles). The "then" rows share the cache of the
rows before them (what was compiled is loaded; the second run compiles the step loop,
``dvqp.motion.follow.COMPILE``). For each command it prints the wall time, the
CPU time of the process (user + sys), how many numba functions it compiled, how long its first
line on stderr took to come (the compile announcement) and the estimate that line gave, and,
where issue 33/37 set one, the target and whether it is met. Run it with nothing else busy: the
CPU figures include no other process, the wall figures do.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from checkout import ROOT  # before dvqp: this checkout's, not an installed one

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
print("@@" + json.dumps({"compiled": len(compiled), "code": code}), file=sys.stderr)
"""
ESTIMATE = re.compile(r"about (\d+) s")

TARGETS = {"--help": 2.0, "plan": 20.0, "compare": 30.0}
"""s of CPU with empty caches (issues 33 and 37)."""


def measure(args: list[str], env: dict[str, str]) -> dict[str, float | str]:
    """Wall time, CPU (user + sys, s), compiled functions, exit code, the first stderr line's
    delay (s) and estimate of ``dvqp <args>`` in a fresh process (``import``: the import)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    process = subprocess.Popen(
        [sys.executable, "-c", PROBE, *args],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    lines: list[tuple[float, str]] = []

    def read() -> None:
        assert process.stderr is not None
        for line in process.stderr:
            lines.append((time.perf_counter() - started, line.rstrip("\n")))

    reader = threading.Thread(target=read)
    reader.start()
    process.wait()
    reader.join()
    wall = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    found = json.loads(next(text[2:] for _, text in reversed(lines) if text.startswith("@@")))
    said = [(at, text) for at, text in lines if not text.startswith("@@")]
    first = said[0][0] if said else float("nan")
    estimate = next((m.group(1) for _, t in said if (m := ESTIMATE.search(t))), "")
    return {"wall": wall, "cpu": cpu, "first": first, "estimate": estimate, **found}


def fresh(tmp: Path, name: str) -> dict[str, str]:
    """The environment of a fresh clone: empty numba cache, home and cache folders."""
    env = {**os.environ, "MPLBACKEND": "Agg"}
    for key in ("NUMBA_CACHE_DIR", "HOME", "XDG_CACHE_HOME"):
        folder = tmp / name / key.lower()
        folder.mkdir(parents=True)
        env[key] = str(folder)
    return env


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default="scenes/paper-two-inlets.toml")
    parser.add_argument("--backend", default="daqp")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        trajectory = str(tmp / "run.npz")
        env = fresh(tmp, "plan")
        runs = [
            ("cold: import dvqp", ["import"], fresh(tmp, "import")),
            ("cold: dvqp --help", ["--help"], fresh(tmp, "help")),
            ("cold: dvqp backends", ["backends"], fresh(tmp, "backends")),
            (
                f"cold: dvqp plan ({args.backend})",
                ["plan", args.scene, "--backend", args.backend, "-o", trajectory],
                env,
            ),
            ("then: dvqp plot", ["plot", trajectory, "-o", str(tmp / "run.png")], env),
            (
                "then: dvqp plan (its step loop compiles)",
                ["plan", args.scene, "--backend", args.backend],
                env,
            ),
            ("then: dvqp plan (all cached)", ["plan", args.scene, "--backend", args.backend], env),
            ("then: dvqp compare (every backend)", ["compare", args.scene], env),
            (
                "cold: dvqp compare (README's first command)",
                ["compare", args.scene],
                fresh(tmp, "c"),
            ),
            ("cold: dvqp bench (2 scenes)", ["bench", "--count", "2"], fresh(tmp, "bench")),
            (
                "cold: dvqp export-qps",
                ["export-qps", args.scene, "--backend", args.backend, "-o", str(tmp / "qps")],
                fresh(tmp, "export"),
            ),
        ]
        for label, command, environment in runs:
            rows.append((label, command[0], measure(command, environment)))
    print(
        f"{'command':<45} {'wall s':>7} {'cpu s':>7} {'compiled':>8} {'1st line':>8} "
        f"{'said':>5} {'target':>7} {'exit':>4}"
    )
    for label, verb, m in rows:
        target = TARGETS.get(verb) if label.startswith("cold") else None
        met = "" if target is None else f"{'<=' if m['cpu'] <= target else '> '}{target:.0f}"
        said = f"{m['estimate']}s" if m["estimate"] else ""
        print(
            f"{label:<45} {m['wall']:7.2f} {m['cpu']:7.2f} {m['compiled']:8.0f} "
            f"{m['first']:8.2f} {said:>5} {met:>7} {m['code']:4.0f}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
