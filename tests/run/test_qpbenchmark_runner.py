"""qpbenchmark's own runner benchmarks an export as it is: the test set ``dvqp export-qps``
writes beside the problems (``dvqp_qps.py``), qpbenchmark's command line, its results and its
report."""

from __future__ import annotations

import csv
import re
import subprocess
import sys
from pathlib import Path

import pytest

import dvqp
from dvqp.run.qp_export import TEST_SET, Exported
from tests.run.test_export_qps import SCENE

qpbenchmark = pytest.importorskip("qpbenchmark")

SETTINGS = ("default", "high_accuracy", "low_accuracy", "mid_accuracy")
"""qpbenchmark's tiers (its ``TestSet.define_solver_settings``)."""


@pytest.fixture(scope="module")
def benchmarked(tmp_path_factory: pytest.TempPathFactory) -> tuple[Exported, Path]:
    """A short run's export (80 steps: 111 problems, 32 of them infeasible) and the folder of
    qpbenchmark's results, DAQP run under every tier by qpbenchmark's command line."""
    root = tmp_path_factory.mktemp("qpbenchmark")
    scene = root / "clamp-ahead.toml"
    scene.write_text(SCENE, encoding="utf-8")
    export = dvqp.export_qps(dvqp.load_scene(scene), "daqp", root / "qps")
    results = root / "results"
    results.mkdir()
    argv = [
        sys.executable,
        "-m",
        "qpbenchmark.benchmark",
        str(export.folder / TEST_SET),
        "--results-path",
        str(results / "dvqp_qps.csv"),
        "run",
        "--solver",
        "daqp",
        "--author",
        "dvqp-tests",
    ]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    return export, results


def test_the_runner_loads_every_problem_of_the_export_by_its_files_name(benchmarked) -> None:
    export, results = benchmarked
    with (results / "dvqp_qps.csv").open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    names = [Path(e["file"]).stem for e in export.index["problems"]]
    assert len(names) == 111
    assert sorted((r["problem"], r["settings"]) for r in rows) == sorted(
        (name, tier) for name in names for tier in SETTINGS
    )
    assert {r["solver"] for r in rows} == {"daqp"}


def test_daqp_solves_every_problem_dvqp_answered_in_every_tier_by_qpbenchmarks_check(
    benchmarked,
) -> None:
    """qpbenchmark's success: found, and the residuals and duality gap (finite now) within the
    tier's tolerance; its report's success rate is the share of problems dvqp answered."""
    export, results = benchmarked
    answered = {Path(e["file"]).stem: e["found"] for e in export.index["problems"]}
    with (results / "dvqp_qps.csv").open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        assert (row["found"] == "True") == answered[row["problem"]], row
        if answered[row["problem"]]:
            gap = float(row["duality_gap"])
            assert gap < 1e-9 and float(row["primal_residual"]) < 1e-9, row
    report = (results / "dvqp_qps.md").read_text(encoding="utf-8")
    share = 100.0 * sum(answered.values()) / len(answered)
    for tier in ("Default", "High accuracy", "Low accuracy", "Mid accuracy"):
        section = report.split(f"### {tier} settings")[1].split("###")[0]
        rate = re.search(r"^\| daqp\s*\|\s*([\d.]+) \|", section, re.MULTILINE)
        assert rate is not None, tier
        assert float(rate.group(1)) == pytest.approx(share, abs=0.05) == 71.2
