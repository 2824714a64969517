"""``dvqp bench`` on a Dask LocalCluster gives the outcomes of a local run (needs dvqp[dask])."""

from __future__ import annotations

import pytest

pytest.importorskip("dask.distributed")

from dvqp.bench import generate_scenes, outcome_differences, run_suite

BACKENDS = ("pinv", "daqp", "osqp")


def test_a_local_cluster_gives_the_same_outcomes_as_a_local_run() -> None:
    scenes = generate_scenes(11, 2)
    local = run_suite(scenes, BACKENDS, seed=11)
    ready = []
    on_dask = run_suite(scenes, BACKENDS, seed=11, scheduler="local", ready=ready.append)
    assert len(on_dask.rows) == len(local.rows) == 6
    assert outcome_differences(local.rows, on_dask.rows, tol=1e-9) == []
    assert [(r["scene"], r["backend"]) for r in on_dask.rows] == [
        (r["scene"], r["backend"]) for r in local.rows
    ]
    where = on_dask.where
    assert (where.kind, where.scheduler, where.workers) == ("dask", "local", 1)
    assert ready == [where] and not where.parallel
    assert on_dask.summary.keys() == local.summary.keys()
    for backend in BACKENDS:
        mine, theirs = local.summary[backend], on_dask.summary[backend]
        for key in ("succeeded", "failed_steps", "relaxed_steps", "worst_task_error"):
            assert mine[key] == theirs[key]
