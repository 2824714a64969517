"""``dvqp bench`` on a Dask LocalCluster gives the outcomes of a local run (needs dvqp[dask])."""

from __future__ import annotations

import os
import time
from dataclasses import replace
from pathlib import Path

import pytest

pytest.importorskip("dask.distributed")

from dvqp.bench import dask_run, execution, generate_scenes, outcome_differences, run_suite

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
    assert ready == [replace(where, startup=())] and not where.parallel
    assert len(where.startup) == 1 and where.startup[0] >= 0
    assert on_dask.summary.keys() == local.summary.keys()
    for backend in BACKENDS:
        mine, theirs = local.summary[backend], on_dask.summary[backend]
        for key in ("succeeded", "failed_steps", "relaxed_steps", "worst_task_error"):
            assert mine[key] == theirs[key]


def test_a_scene_running_past_the_timeout_is_given_up_and_reported(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    real = dask_run.run_job

    def slow(job: dask_run.Job) -> list:
        if job.index == 1:
            time.sleep(4.0)  # a worker thread cannot be stopped: it ends on its own
        return real(job)

    monkeypatch.setattr(dask_run, "run_job", slow)  # the cluster's threads run it
    scenes = generate_scenes(11, 3)
    suite = run_suite(scenes, ["pinv"], seed=11, scheduler="local", workers=2, scene_timeout=1.5)
    assert [(r["index"], r["error"]) for r in suite.rows if r["steps"] is None] == [
        (1, "timed out after 1.5 s")
    ]
    assert [r["index"] for r in suite.rows] == [0, 1, 2] and not suite.interrupted
    assert suite.summary["pinv"]["lost"] == suite.summary["pinv"]["raised"] == 1


def test_a_local_cluster_runs_every_scene_once_in_worker_processes_forked_warm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    log, real = tmp_path / "runs.txt", execution.run_job

    def logged(job: dask_run.Job, *args: object) -> list:
        with log.open("a") as file:
            file.write(f"{os.getpid()} {job.index}\n")
        return real(job, *args)

    monkeypatch.setattr(execution, "_WARM", set())  # as in a fresh process
    for module in (execution, dask_run):  # here and in warm_up / the tasks (pickled)
        monkeypatch.setattr(module, "run_job", logged)
    scenes = generate_scenes(11, 6)
    suite = run_suite(scenes, ["pinv", "daqp"], seed=11, scheduler="local", workers=2)
    runs = [tuple(map(int, line.split())) for line in log.read_text().splitlines()]
    shortest = min(scenes, key=lambda s: (s.steps, s.index)).index
    assert runs[0] == (os.getpid(), shortest)  # the shortest here, before the cluster forked
    assert sorted(index for _, index in runs) == list(range(6))  # no scene twice, no warm-up
    assert all(pid != os.getpid() for pid, _ in runs[1:])
    assert [(r["index"], r["backend"]) for r in suite.rows] == [
        (i, b) for i in range(6) for b in ("pinv", "daqp")
    ]
    assert len(suite.where.startup) == 2 and min(suite.where.startup) >= 0
    assert "worker start-up" in suite.where.describe()
