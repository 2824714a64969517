"""The bench's summary maths: shifted geometric means, per-backend figures, agreement."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest

from dvqp.bench import (
    bench_json,
    make_suite,
    outcome_differences,
    qp_disagreement,
    rows_to_csv,
    shifted_geometric_mean,
    summarize_backends,
)
from dvqp.bench.execution import Where
from dvqp.errors import ParameterError


def row(scene: str, backend: str, step: float | None, solve: float | None, **more: Any) -> dict:
    """A result row with the keys the summary reads."""
    base = {
        "index": int(scene[-1]),
        "scene": scene,
        "backend": backend,
        "success": True,
        "steps": 100,
        "failures": 0,
        "relaxed": 0,
        "substepped": 0,
        "error": None,
        "mean_step_us": step,
        "mean_solve_us": solve,
        "max_limit_excess": 0.0,
        "max_task_error": 1e-15,
        "final_tool": [0.3, 0.35, 0.08, 0.0],
    }
    return {**base, **more}


def test_the_shifted_geometric_mean_matches_a_hand_computation() -> None:
    # (100 + 10) * (1000 + 10) = 111100; its square root is 333.316...; less the shift.
    assert shifted_geometric_mean([100.0, 1000.0], 10.0) == pytest.approx(math.sqrt(111100) - 10)
    assert shifted_geometric_mean([5.0, 5.0, 5.0], 10.0) == pytest.approx(5.0)
    # A larger shift weighs the short times less: from the geometric mean (10) toward the
    # arithmetic mean (50.5).
    big = shifted_geometric_mean([1.0, 100.0], 1000.0)
    assert big == pytest.approx(math.sqrt(1001 * 1100) - 1000) and 49 < big < 50.5
    for bad in ([], [-1.0], [float("nan")]):
        with pytest.raises(ParameterError):
            shifted_geometric_mean(bad, 10.0)


def test_backends_are_compared_on_the_scenes_every_backend_ran() -> None:
    rows = [
        row("s0", "pinv", 100.0, 10.0),
        row("s0", "daqp", 300.0, 200.0),
        row("s1", "pinv", 200.0, 20.0),
        row("s1", "daqp", 500.0, 400.0),
        row("s2", "pinv", 100.0, 10.0),  # daqp raised on s2: no timing, s2 left out
        row(
            "s2",
            "daqp",
            None,
            None,
            success=False,
            steps=None,
            failures=None,
            relaxed=None,
            substepped=None,
            final_tool=None,
            error="boom",
            max_limit_excess=None,
            max_task_error=None,
        ),
    ]
    s = summarize_backends(rows, ["pinv", "daqp"], shift=10.0)
    pinv = math.sqrt(110 * 210) - 10
    daqp = math.sqrt(310 * 510) - 10
    assert s["pinv"]["step_time_sgm_us"] == pytest.approx(pinv)
    assert s["daqp"]["step_time_sgm_us"] == pytest.approx(daqp)
    assert s["pinv"]["step_time_sgm_ratio"] == pytest.approx(1.0)
    assert s["daqp"]["step_time_sgm_ratio"] == pytest.approx(daqp / pinv)
    assert s["daqp"]["solve_time_sgm_us"] == pytest.approx(math.sqrt(210 * 410) - 10)
    assert s["daqp"]["timed_scenes"] == 2
    assert s["daqp"]["runs"] == 3 and s["daqp"]["succeeded"] == 2 and s["daqp"]["raised"] == 1
    assert s["daqp"]["success_rate"] == pytest.approx(2 / 3)
    assert s["pinv"]["success_rate"] == 1.0


def test_step_counts_and_worst_figures_are_summed_and_maximised() -> None:
    rows = [
        row(
            "s0",
            "osqp",
            1.0,
            1.0,
            failures=2,
            relaxed=5,
            success=False,
            max_limit_excess=3e-5,
            refused_calls=6,
            capped_calls=1,
        ),
        row("s1", "osqp", 1.0, 1.0, relaxed=7, max_task_error=0.04, refused_calls=7),
    ]
    s = summarize_backends(rows, ["osqp"])["osqp"]
    assert (s["failed_steps"], s["relaxed_steps"], s["succeeded"]) == (2, 12, 1)
    assert (s["refused_calls"], s["capped_calls"]) == (13, 1)
    assert s["worst_limit_excess"] == 3e-5 and s["worst_task_error"] == 0.04


def test_qp_disagreement_is_the_largest_spread_among_successful_qp_runs() -> None:
    rows = [
        row("s0", "pinv", 1, 1, final_tool=[9.0, 9.0, 9.0, 0.0]),  # the baseline: not a QP
        row("s0", "daqp", 1, 1, final_tool=[0.3, 0.35, 0.08, 0.0]),
        row("s0", "osqp", 1, 1, final_tool=[0.3, 0.35 + 3e-6, 0.08 + 4e-6, 0.1]),
        row("s0", "clarabel", 1, 1, final_tool=[1.0, 1.0, 1.0, 0.0], success=False),
        row("s1", "daqp", 1, 1),
        row("s1", "osqp", 1, 1),
    ]
    d = qp_disagreement(rows)
    assert d["max_spread_m"] == pytest.approx(5e-6)
    assert d["scene"] == "s0" and d["backends"] == ["daqp", "osqp"]
    assert d["scenes_compared"] == 2
    s = summarize_backends(rows, ["pinv", "daqp", "osqp", "clarabel"])
    assert s["daqp"]["max_distance_to_qp_median_m"] == pytest.approx(2.5e-6)
    assert s["pinv"]["max_distance_to_qp_median_m"] > 10
    assert s["clarabel"]["max_distance_to_qp_median_m"] is None
    assert qp_disagreement(rows[:2])["max_spread_m"] is None


def test_outcome_differences_ignore_timings_but_not_final_tools() -> None:
    a = [row("s0", "daqp", 100.0, 50.0)]
    assert outcome_differences(a, [row("s0", "daqp", 900.0, 70.0)]) == []
    near = [row("s0", "daqp", 1, 1, final_tool=[0.3 + 1e-12, 0.35, 0.08, 0.0])]
    assert outcome_differences(a, near) == []
    far = [row("s0", "daqp", 1, 1, final_tool=[0.3 + 1e-6, 0.35, 0.08, 0.0], relaxed=1)]
    found = outcome_differences(a, far)
    assert len(found) == 2 and "relaxed" in found[0] and "final_tool" in found[1]
    assert outcome_differences(a, []) == ["s0 / daqp: only in one"]


def test_json_and_csv_of_a_suite_hold_no_nan() -> None:
    rows = [row("s0", "pinv", 1.0, 1.0, min_clearance=math.inf, p95_step_us=math.nan)]
    suite = make_suite(rows, ["pinv"], seed=3, count=1, where=Where("local", 4))
    doc = json.loads(bench_json(suite))
    assert doc["results"][0]["min_clearance"] is None and doc["results"][0]["parallel"] is True
    assert doc["execution"] == {
        "kind": "local",
        "workers": 4,
        "scheduler": None,
        "startup": [],
        "parallel": True,
    }
    assert {"results", "summary", "machine", "versions", "seed", "count"} <= set(doc)
    lines = rows_to_csv(suite).splitlines()
    assert len(lines) == 2 and "nan" not in lines[1].lower() and "inf" not in lines[1].lower()
