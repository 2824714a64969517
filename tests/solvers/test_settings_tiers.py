"""Settings tiers (qpbenchmark's default / high / low accuracy) and the accuracy figures they
move: every backend takes its tier's settings, the tier changes what the solver does and what
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
from solvers.tiers import EPS, SETTING_NAMES, TIERS, tier_settings
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
            assert backend.tolerance == EPS[tier]


def test_an_unknown_tier_is_refused_naming_the_tiers() -> None:
    with pytest.raises(ValueError, match="tiers: default, high_accuracy, low_accuracy"):
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
    assert set(rows) - {"solver", "---"} == set(SETTING_NAMES)
    for solver, groups in SETTING_NAMES.items():
        cells = [c.strip() for c in rows[solver].split("|")[2:5]]
        for cell, names in zip(cells, groups, strict=True):
            assert re.findall(r"`(\w+)`", cell) == list(names), solver


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
