"""``solvers``' numba kernels: nothing compiled on import, each compiled once on first use (its
import graph is checked with dvqp's in tests/package/test_architecture.py)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "solvers"


#: Run in a fresh interpreter: the kernels' state after ``import solvers``, then after DAQP
#: and OSQP solves and ``solvers.residuals``, each on a read-only (validated) and a writable
#: (trusted) problem.
PROBE = """
import json
from collections import Counter
import numpy as np
from numba.core import event
from numba.core.dispatcher import Dispatcher

compiled = Counter()

class Count(event.Listener):
    def on_start(self, ev):
        function = ev.data["dispatcher"].py_func
        compiled[f"{function.__module__}.{function.__qualname__}"] += 1

    def on_end(self, ev):
        pass

event.register("numba:compile", Count())
import solvers
from solvers import _fast, _kkt, daqp_c

kernels = {
    f"{module.__name__}.{name}": value
    for module in (_fast, _kkt, daqp_c)
    for name, value in vars(module).items()
    if isinstance(value, Dispatcher)
}

def state():
    return {
        "compiled": {k: v for k, v in compiled.items() if k.startswith("solvers.")},
        "overloads": {name: len(d.overloads) for name, d in kernels.items()},
    }

report = {"import": state()}
data = dict(
    P=np.diag([2.0, 3.0, 4.0]), q=np.array([-1.0, 1.0, -2.0]),
    A=np.ones((1, 3)), b=np.array([0.5]), G=np.array([[1.0, -1.0, 0.0]]),
    h=np.array([0.1]), lb=np.full(3, -1.0), ub=np.array([1.0, 1.0, np.inf]),
)
problems = (solvers.Problem(**data), solvers.Problem.trusted(**data))
for name in ("daqp", "osqp"):
    for problem in problems:
        backend = solvers.make_backend(name)
        for _ in range(3):
            solution = backend.solve(problem)
            assert solution.found, solution.message
            solvers.residuals(problem, solution.x, solution.y, solution.z, solution.z_box)
    report[name] = state()
report["can_compile"] = {name: d._can_compile for name, d in kernels.items()}
from solvers import daqp_abi
report["daqp_c"] = daqp_abi.available()
print(json.dumps(report))
"""

#: The kernels with a declared signature (the others are the helpers they call).
DECLARED = (
    "solvers._fast.refresh",
    "solvers._fast.stack",
    "solvers._kkt.kernel",
    "solvers._kkt.stacked",
    "solvers.daqp_c.solve_stacked",
)
#: The declared kernels of DAQP's two ways (solvers.daqp_): its C functions called from
#: compiled code, and daqp.Model's; only those of the way taken are compiled.
C_WAY = ("solvers.daqp_c.solve_stacked",)
MODEL_WAY = ("solvers._fast.stack", "solvers._kkt.stacked")


def test_kernels_compile_at_their_first_call_one_specialisation_each() -> None:
    run = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr
    report = json.loads(run.stdout.splitlines()[-1])
    assert report["import"]["compiled"] == {}
    assert set(report["import"]["overloads"]) >= set(DECLARED)
    assert not any(report["import"]["overloads"].values())  # nothing compiled nor loaded
    final = report["osqp"]
    assert all(count <= 1 for count in final["compiled"].values()), final  # 0: from the cache
    unused = MODEL_WAY if report["daqp_c"] else C_WAY
    for name, count in final["overloads"].items():  # read-only and writable calls: one each
        if name in unused:
            assert count == 0 and report["can_compile"][name], name
            continue
        # a declared kernel: its one signature; a helper (the residuals' body, which both
        # residual kernels call on read-only arrays, and its parts): at most one
        # specialisation (none where its caller's code, linked in, came from the cache)
        assert count == 1 if name in DECLARED else count <= 1, (name, final)
        assert report["can_compile"][name] == (name not in DECLARED), name
