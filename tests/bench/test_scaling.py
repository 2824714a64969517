"""A local pool: the first scene here, workers forked warm from this process, every scene run
once, the outcomes of a serial run, each worker's start-up reported; scenes drawn in chunks."""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

import pytest

from dvqp.bench import Job, execution, generate_scenes, outcome_differences, run_suite
from dvqp.bench.execution import generate_local
from dvqp.bench.suite import longest_first

BACKENDS = ("pinv", "daqp")


@pytest.mark.parametrize("count", [1, 2, 9, 23])
def test_scenes_drawn_by_a_pool_are_those_drawn_one_by_one(count: int) -> None:
    assert generate_local(11, count, 2) == generate_scenes(11, count)


def test_warm_up_runs_a_scene_only_for_backends_this_process_has_not_run(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[int] = []
    monkeypatch.setattr(execution, "run_job", lambda job, *_: calls.append(job.index) or [])
    monkeypatch.setattr(execution, "_WARM", set())
    for index, backends in enumerate([("pinv", "daqp"), ("daqp",), ("pinv", "osqp"), ("osqp",)]):
        assert execution.warm_up(Job(index, f"s{index}", "", backends)) >= 0
    assert calls == [0, 2]


def logged_runs(monkeypatch: pytest.MonkeyPatch, log: Path) -> None:
    """Every ``run_job`` of :mod:`dvqp.bench.execution` (here and in forked workers) appends
    ``<process id> <scene index>`` to ``log``; this process counts as a fresh one."""
    real = execution.run_job

    def logged(job: Job, *args: object) -> list:
        with log.open("a") as file:
            file.write(f"{os.getpid()} {job.index}\n")
        return real(job, *args)

    monkeypatch.setattr(execution, "run_job", logged)
    monkeypatch.setattr(execution, "_WARM", set())


def test_a_pool_runs_the_first_scene_here_then_every_other_once_in_workers_forked_warm(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scenes = generate_scenes(11, 7)
    serial = run_suite(scenes, BACKENDS, seed=11)
    logged_runs(monkeypatch, tmp_path / "runs.txt")
    pooled = run_suite(scenes, BACKENDS, seed=11, workers=2)
    runs = [
        tuple(map(int, line.split()))
        for line in (tmp_path / "runs.txt").read_text().split("\n")
        if line
    ]
    shortest = min(scenes, key=lambda s: (s.steps, s.index)).index
    assert runs[0] == (os.getpid(), shortest)  # the shortest scene warms this process up
    assert sorted(index for _, index in runs) == list(range(7))  # once each: no warm-up run
    workers = {pid for pid, _ in runs[1:]}
    assert os.getpid() not in workers and 1 <= len(workers) <= 2
    assert outcome_differences(serial.rows, pooled.rows, tol=0.0) == []
    assert [r["scene"] for r in pooled.rows] == [r["scene"] for r in serial.rows]
    assert len(pooled.where.startup) == len(workers) and min(pooled.where.startup) >= 0
    assert serial.where.startup == () and "start-up" not in serial.where.describe()


def test_workers_that_cannot_fork_warm_themselves_up_and_give_the_same_outcomes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    scenes = generate_scenes(11, 4)
    serial = run_suite(scenes, ["pinv"], seed=11)
    monkeypatch.setattr(execution, "pool_context", lambda: multiprocessing.get_context("spawn"))
    pooled = run_suite(scenes, ["pinv"], seed=11, workers=2)
    assert outcome_differences(serial.rows, pooled.rows, tol=0.0) == []
    assert [r["index"] for r in pooled.rows] == [0, 1, 2, 3]
    # a spawned worker imports dvqp and runs the first scene before its first task
    assert 1 <= len(pooled.where.startup) <= 2 and min(pooled.where.startup) > 0.1


def test_the_shortest_scene_goes_first_then_the_longest_first() -> None:
    scenes = generate_scenes(11, 12)
    order = longest_first(scenes)
    assert sorted(s.index for s in order) == list(range(12))
    assert order[0].steps == min(s.steps for s in scenes)
    rest = [s.steps for s in order[1:]]
    assert rest == sorted(rest, reverse=True) and len(set(s.steps for s in scenes)) > 2
    assert longest_first(scenes[:1]) == scenes[:1] and longest_first([]) == []
