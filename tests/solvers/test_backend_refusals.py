"""A backend's refused calls are counted per run, named by kind, and never reach stderr as
Python warnings (qpsolvers warns of every failed solve; the step already handled it)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import solvers
from dvqp import Trajectory, load_scene, plan
from dvqp.cli import main
from dvqp.run.comparison import summarize

SCENES = Path(__file__).resolve().parents[2] / "scenes"
INFEASIBLE = solvers.Problem(
    np.eye(3), np.zeros(3), G=np.array([[1.0, 0, 0], [-1.0, 0, 0]]), h=np.array([-1.0, -1.0])
)
"""x1 <= -1 and x1 >= 1."""


@pytest.mark.parametrize("name", solvers.available_backends())
def test_no_backend_warns_of_an_infeasible_problem_and_its_refusal_is_named(name: str) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        solution = solvers.make_backend(name).solve(INFEASIBLE)
    assert [str(w.message) for w in caught] == []
    assert not solution.found
    # a solver that says "infeasible" is named so; else by what it gave: an x or nothing
    silent = "inaccurate" if solution.x is not None else "no answer"
    expected = "infeasible" if "infeas" in solution.status.lower() else silent
    assert solution.refusal == expected


def test_a_refusal_is_named_from_the_status_word_never_accepted_by_it() -> None:
    answer = np.array([5.0, 0.0, 0.0])  # breaks x1 <= -1
    cases = {
        "PROXQP_MAX_ITER_REACHED": "iteration limit",
        "maximum iterations reached": "iteration limit",
        "time limit reached": "time limit",
        "PrimalInfeasible": "infeasible",
        "solved": "inaccurate",
    }
    for status, kind in cases.items():
        solution = solvers.Solution.checked(
            INFEASIBLE, answer, backend="b", tolerance=1e-6, status=status
        )
        assert (solution.found, solution.refusal) == (False, kind), status
    assert set(cases.values()) <= set(solvers.REFUSALS)
    feasible = solvers.Problem(np.eye(3), np.zeros(3))
    solution = solvers.Solution.checked(
        feasible, np.zeros(3), backend="b", tolerance=1e-6, status="PROXQP_MAX_ITER_REACHED"
    )
    assert (solution.found, solution.refusal) == (True, "")  # the check decides, not the word


@pytest.mark.parametrize("backend", ["daqp", "qpsolvers:osqp"])
def test_a_run_counts_the_refused_calls_and_keeps_them_in_its_file(
    backend: str, tmp_path: Path
) -> None:
    pytest.importorskip(backend.split(":")[-1])
    scene = load_scene(SCENES / "probe-into-clamp.toml")
    traj = plan(scene, backend)
    row = summarize(scene, traj)
    assert row["relaxed"] > 0  # the scene makes the task give way
    # every relaxed step's strict problem was refused once; a braking step's relaxed one too
    assert traj.refusals.get("infeasible", 0) >= row["relaxed"]
    assert row["refused_calls"] == sum(traj.refusals.values())
    assert row["refusals"] == traj.refused and traj.refused.endswith("infeasible")
    loaded = Trajectory.load(traj.save(tmp_path / "run.npz"))
    assert loaded.refusals == traj.refusals
    assert plan(scene, "pinv").refusals == {}


def test_the_summary_counts_refused_calls_and_stderr_has_no_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("osqp")
    code = main(["plan", str(SCENES / "probe-into-clamp.toml"), "--backend", "qpsolvers:osqp"])
    out, err = capsys.readouterr()
    assert code == 0 and err == ""
    lines = out.replace("\n" + " " * 18, " ").splitlines()  # wrapped lines joined
    solver_line = next(line for line in lines if line.startswith("solver "))
    assert "calls refused (" in solver_line and "infeasible)" in solver_line


def test_a_bench_row_counts_the_calls_stopped_at_an_iteration_cap() -> None:
    pytest.importorskip("proxsuite")
    from dvqp.bench.runner import Job, run_job

    text = (SCENES / "joint-limit.toml").read_text(encoding="utf-8")
    (row,) = run_job(Job(0, "joint-limit", text, ("proxqp",)))
    traj = plan(load_scene(SCENES / "joint-limit.toml"), "proxqp")
    capped = traj.refusals.get("iteration limit", 0) + traj.refusals.get("time limit", 0)
    assert capped > 0  # ProxQP stops at its cap on a few of this scene's infeasible problems
    assert (row["capped_calls"], row["refused_calls"]) == (capped, sum(traj.refusals.values()))
