"""Start-up cost of the compiled step: a cold run (nothing compiled yet) and a cached one.

Usage::

    python benchmarks/startup.py [SCENE] [--backend daqp]

Each measurement is a fresh Python process timing ``import dvqp`` and one ``dvqp.plan`` of the
scene. "cold" points numba's cache (``NUMBA_CACHE_DIR``) and dvqp's generated drivers
(``DVQP_CACHE_DIR``) at an empty temporary directory, so everything compiles; "cached" runs
again with the same directories, so everything loads. The reference engine is timed too.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROBE = """
import json, sys, time
started = time.perf_counter()
import dvqp
imported = time.perf_counter()
scene = dvqp.load_scene(sys.argv[1])
traj = dvqp.plan(scene, sys.argv[2], engine=sys.argv[3])
done = time.perf_counter()
print(json.dumps({"import": imported - started, "plan": done - imported,
                  "steps": traj.n_steps, "compiled": int(traj.compiled.sum())}))
"""


def measure(scene: str, backend: str, engine: str, env: dict[str, str]) -> dict[str, float]:
    out = subprocess.run([sys.executable, "-c", PROBE, scene, backend, engine], env=env,
                         capture_output=True, text=True, check=True).stdout  # fmt: skip
    return json.loads(out.strip().splitlines()[-1])  # type: ignore[no-any-return]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "paper-two-inlets.toml"))
    parser.add_argument("--backend", default="daqp")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "NUMBA_CACHE_DIR": tmp, "DVQP_CACHE_DIR": tmp}
        runs = [("cold (compiles)", "auto"), ("cached (loads)", "auto"),
                ("reference engine", "reference")]  # fmt: skip
        rows = [(label, measure(args.scene, args.backend, engine, env)) for label, engine in runs]
    print(f"{'start-up':<18} {'import s':>9} {'plan s':>8} {'steps':>6} {'compiled':>9}")
    for label, m in rows:
        print(f"{label:<18} {m['import']:9.2f} {m['plan']:8.2f} {m['steps']:6.0f} "
              f"{m['compiled']:9.0f}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
