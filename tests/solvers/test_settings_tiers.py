"""Settings tiers (dvqp's own default; qpbenchmark's high, mid and low accuracy and its default,
the solvers' own) and the accuracy figures they move: every backend takes its tier's settings,
each qpbenchmark tier is qpbenchmark's own, the tier changes what the solver does and what
dvqp's check accepts, and compare reports the figures for every backend."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import pytest

import solvers
from dvqp import ParameterError, load_scene, plan
from dvqp.cli import main
from dvqp.run.comparison import summarize
from solvers.tiers import CHECK, EPS_ABS, EPS_REL, QPBENCHMARK, TIERS, TIME_LIMITS, tier_settings
from tests.cli.test_cli import write_scene

DOCS = Path(__file__).resolve().parents[2] / "docs" / "cli.md"


@pytest.mark.parametrize("tier", TIERS)
def test_every_installed_backend_takes_its_tiers_settings(tier: str) -> None:
    for name in solvers.available_backends():
        settings = tier_settings(name, tier)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            backend = solvers.make_backend(name, **settings)  # probes them on a small QP
        assert backend.tolerance == settings.get("tolerance", backend.tolerance)
        if tier != "default":
            assert backend.tolerance == CHECK[tier]


def test_an_unknown_tier_is_refused_naming_the_tiers() -> None:
    tiers = "tiers: default, high_accuracy, mid_accuracy, low_accuracy, solver_defaults"
    with pytest.raises(ValueError, match=tiers):
        tier_settings("osqp", "extreme")
    scene = load_scene(write_scene_path())
    with pytest.raises(ParameterError, match=r"^settings: unknown tier 'extreme'"):
        plan(scene, "daqp", tier="extreme")


def write_scene_path() -> str:
    return str(Path(__file__).resolve().parents[2] / "scenes" / "paper-two-inlets.toml")


def test_the_docs_table_lists_each_solvers_tier_settings() -> None:
    text = DOCS.read_text("utf-8")
    table = text.split("<!-- tier-settings:")[1].split("<!-- end tier-settings -->")[0]
    rows = {line.split("|")[1].strip(): line for line in table.splitlines() if line.count("|") == 5}
    solvers_named = set(EPS_ABS) | set(TIME_LIMITS)
    assert set(rows) - {"solver", "---"} == solvers_named
    for solver in solvers_named:
        cells = [c.strip() for c in rows[solver].split("|")[2:5]]
        expected = (list(EPS_ABS.get(solver, {})), list(EPS_REL.get(solver, ())))
        assert [re.findall(r"`(\w+)`", cell) for cell in cells[:2]] == list(expected), solver
        time_limit = [TIME_LIMITS[solver]] if solver in TIME_LIMITS else []
        assert re.findall(r"`(\w+)`", cells[2]) == time_limit, solver


def qpbenchmark_test_set():  # type: ignore[no-untyped-def]
    """A qpbenchmark test set of no problem, whose tiers (settings, tolerances) are read."""
    qpbenchmark = pytest.importorskip("qpbenchmark")

    class Empty(qpbenchmark.TestSet):
        description = title = "tiers"
        sparse_only = False

        def __iter__(self):  # type: ignore[no-untyped-def]
            return iter(())

    return Empty()


@pytest.mark.parametrize("tier", [t for t in TIERS if t != "default"])
def test_each_qpbenchmark_tier_gives_every_backend_qpbenchmarks_own_settings(tier: str) -> None:
    """The settings a backend ends up with are those qpbenchmark gives the solver in that tier
    (its ``TestSet`` read, not a copy), plus only the adapter's own needs (quiet, Clarabel's
    data updates, OSQP's failures as a status), none of them about accuracy; the check's
    tolerance is the tier's validation tolerance."""
    test_set = qpbenchmark_test_set()
    implemented = pytest.importorskip("qpbenchmark.solver_settings").SolverSettings
    theirs = test_set.solver_settings[QPBENCHMARK[tier]]
    for solver in implemented.IMPLEMENTED_SOLVERS:  # installed or not
        assert solvers.tiers.solver_settings(solver, tier) == theirs[solver], solver
    tolerance = test_set.tolerances[QPBENCHMARK[tier]]
    if tier != "solver_defaults":  # qpbenchmark validates its default tier at 1.0
        assert CHECK[tier] == tolerance.primal == tolerance.dual == tolerance.gap
    for name in solvers.available_backends():
        solver = name.removeprefix("qpsolvers:")
        if solver not in implemented.IMPLEMENTED_SOLVERS:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            backend = solvers.make_backend(name, **tier_settings(name, tier))
        own = {k: v for k, v in backend.settings.items() if k not in theirs[solver]}
        assert set(own) <= {"verbose", "presolve_enable", "raise_error"}, (name, own)
        assert own.get("verbose", False) is False and own.get("raise_error", False) is False
        assert {k: backend.settings[k] for k in theirs[solver]} == theirs[solver], name


def test_osqp_polishes_in_dvqps_default_only() -> None:
    pytest.importorskip("osqp")
    for tier in TIERS:
        for name in ("osqp", "qpsolvers:osqp"):
            backend = solvers.make_backend(name, **tier_settings(name, tier))
            assert backend.settings.get("polishing", False) is (tier == "default"), (tier, name)


def test_a_tier_changes_what_osqp_does_and_the_accuracy_reported() -> None:
    pytest.importorskip("osqp")
    scene = load_scene(write_scene_path())
    figures = {}
    for tier in ("high_accuracy", "low_accuracy"):
        traj = plan(scene, "osqp", tier=tier)
        figures[tier] = summarize(scene, traj, tier)
    high, low = figures["high_accuracy"], figures["low_accuracy"]
    assert high["success"] and low["success"]
    assert high["settings"] == "high_accuracy"
    assert high["median_iterations"] > low["median_iterations"]  # asked for more, works more
    for name in ("primal_residual", "dual_residual", "duality_gap"):
        assert 0.0 <= high[name] < 1e-9 < low[name] < 1e-3, name
    assert 0.9 * high["steps"] < high["qp_solves"]  # one a step (stops at rest may need none)


def test_compare_reports_accuracy_for_every_qp_backend_and_none_for_the_baseline(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    pytest.importorskip("osqp")
    out = tmp_path / "r.json"
    argv = [
        "compare",
        write_scene(tmp_path),
        "--backends",
        "pinv,daqp,osqp",
        "--settings",
        "high_accuracy",
        "--json",
        str(out),
        "--wide",
    ]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("settings: high_accuracy\n")
    assert {"r_prim", "r_dual", "gap"} <= set(printed.splitlines()[1].split())
    doc = json.loads(out.read_text("utf-8"))
    assert doc["settings"] == "high_accuracy"
    for row in doc["results"]:
        values = [row[k] for k in ("primal_residual", "dual_residual", "duality_gap")]
        if row["backend"] == "pinv":
            assert values == [None] * 3 and row["qp_solves"] is None
        else:
            assert all(0.0 <= v < 1e-9 for v in values) and row["qp_solves"] > 0


def test_compare_check_ignores_the_baselines_broken_limits(tmp_path: Path) -> None:
    pytest.importorskip("daqp")
    # the paper's baseline breaks the lower inlet's margin; the QP run is ok
    argv = ["compare", write_scene_path(), "--backends", "pinv,daqp", "--check"]
    assert main(argv) == 0


def test_bench_runs_under_a_tier_and_merges_every_calls_accuracy(tmp_path: Path) -> None:
    pytest.importorskip("daqp")
    out = tmp_path / "b.json"
    argv = [
        "bench",
        "--count",
        "2",
        "--seed",
        "1",
        "--backends",
        "pinv,daqp",
        "--settings",
        "high_accuracy",
        "--check",
        "--json",
        str(out),
    ]
    assert main(argv) == 0
    doc = json.loads(out.read_text("utf-8"))
    runs = [r for r in doc["results"] if r["backend"] == "daqp"]
    assert {r["settings"] for r in doc["results"]} == {"high_accuracy"}
    merged = doc["summary"]["daqp"]
    assert merged["qp_solves"] == sum(r["qp_solves"] for r in runs) > 0
    for name in ("primal_residual", "dual_residual", "duality_gap"):  # between the runs' own
        values = [r[name] for r in runs]
        assert min(values) <= merged[name] <= max(values)
    assert doc["summary"]["pinv"]["primal_residual"] is None
