"""``dvqp bench`` when things go wrong: a killed pool worker, a killed bench, Ctrl-C, a Dask
cluster that loses its workers. Real processes and signals (Linux), on the shared warm cache."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux signals")

BENCH = [sys.executable, "-m", "dvqp", "bench", "--seed", "3", "--backends", "pinv,daqp"]
ENV = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2])}


@pytest.fixture(scope="module", autouse=True)
def warm() -> None:
    """Both backends' kernels compiled (or loaded) once, before anything is timed."""
    done = subprocess.run([*BENCH, "--count", "1"], capture_output=True, env=ENV, timeout=300)
    assert done.returncode == 0, done.stderr


def start(*argv: str, script: str | None = None) -> subprocess.Popen[str]:
    """``dvqp bench --seed 3 --backends pinv,daqp ARGV`` in a new process (through ``script``,
    Python run before the command line, if given)."""
    cmd = BENCH if script is None else [sys.executable, "-c", script, *BENCH[3:]]
    return subprocess.Popen(
        [*cmd, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV
    )


def scenes_in(partial: Path, at_least: int, timeout: float = 60.0) -> list[dict]:
    """Wait until ``partial`` holds the results of ``at_least`` scenes; its results."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        lines = partial.read_text().splitlines() if partial.exists() else []
        rows = [json.loads(line) for line in lines]
        if len({r["index"] for r in rows}) >= at_least:
            return rows
        time.sleep(0.05)
    raise AssertionError(f"{partial}: fewer than {at_least} scenes in {timeout} s")


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def indices(doc: dict) -> list[int]:
    return sorted({r["index"] for r in doc["results"]})


def finished(proc: subprocess.Popen[str], out: Path) -> tuple[dict, str]:
    """Wait for the bench ``proc``; check it ended well (exit 0, no traceback); its ``--json``
    document ``out`` and what it printed."""
    printed, err = proc.communicate(timeout=120)
    assert proc.returncode == 0 and "Traceback" not in err, err
    return json.loads(out.read_text()), printed


def none_lost(doc: dict, count: int) -> None:
    """Every one of the ``count`` scenes ran (two backends each), none reported lost."""
    assert indices(doc) == list(range(count)) and len(doc["results"]) == 2 * count
    assert not any(r["error"] == "worker lost" for r in doc["results"])


def test_results_are_on_disk_scene_by_scene_even_if_the_bench_is_killed(tmp_path: Path) -> None:
    out = tmp_path / "a.json"
    proc = start("--count", "40", "--json", str(out))
    rows = scenes_in(tmp_path / "a.json.partial", 2)
    proc.kill()  # SIGKILL: nothing runs after it
    proc.communicate(timeout=30)
    assert not out.exists()
    rows = [json.loads(line) for line in (tmp_path / "a.json.partial").read_text().splitlines()]
    assert len(rows) >= 4 and len(rows) % 2 == 0  # whole scenes, every line complete
    pairs = [(r["index"], r["backend"]) for r in rows[:4]]  # two whole scenes, in run order
    assert [b for _, b in pairs] == ["pinv", "daqp", "pinv", "daqp"]
    assert pairs[0][0] == pairs[1][0] != pairs[2][0] == pairs[3][0]
    assert all(r["steps"] > 0 and len(r["final_tool"]) == 4 for r in rows)


def test_a_killed_pool_worker_costs_nothing_its_scene_is_run_again(tmp_path: Path) -> None:
    out = tmp_path / "a.json"
    proc = start(
        "--count", "16", "--workers", "2", "--json", str(out), "--csv", str(tmp_path / "a.csv")
    )
    scenes_in(tmp_path / "a.json.partial", 1)  # the first, run here: the pool starts next
    deadline = time.monotonic() + 30.0
    while not (workers := children(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert workers, "no pool process found"
    os.kill(workers[0], signal.SIGKILL)  # as the OOM killer does
    doc, _ = finished(proc, out)
    none_lost(doc, 16)
    assert doc["interrupted"] is False and doc["summary"]["daqp"]["lost"] == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "a.json"]  # no .partial


DEADLY = textwrap.dedent("""
    import os, signal, sys
    from dvqp.bench import execution
    from dvqp.cli import main
    real = execution.run_job
    def deadly(job, *args):  # scene 2 kills its worker process, every time
        if job.index == 2:
            os.kill(os.getpid(), signal.SIGKILL)
        return real(job, *args)
    execution.run_job = deadly
    sys.exit(main(sys.argv[1:]))
""")


def test_a_scene_that_kills_its_worker_again_is_reported_lost(tmp_path: Path) -> None:
    out = tmp_path / "a.json"
    proc = start("--count", "6", "--workers", "2", "--json", str(out), script=DEADLY)
    doc, printed = finished(proc, out)
    assert indices(doc) == list(range(6)) and len(doc["results"]) == 12
    lost = [(r["index"], r["backend"]) for r in doc["results"] if r["error"] == "worker lost"]
    assert lost == [(2, "pinv"), (2, "daqp")]
    assert all(r["steps"] > 0 for r in doc["results"] if r["index"] != 2)
    assert doc["summary"]["pinv"]["lost"] == doc["summary"]["daqp"]["lost"] == 1
    assert "1 scene (worker lost or timed out: no figures): bench-s3-0002" in printed


RACING = textwrap.dedent("""
    import os, signal, sys, time
    from concurrent.futures import ProcessPoolExecutor
    from dvqp.bench import execution
    from dvqp.cli import main

    class Racing(ProcessPoolExecutor):
        # a pool process dies after the last wait and before the next scene is handed over:
        # the pool is broken by then, and its submit raises BrokenProcessPool
        handed = 0
        def submit(self, fn, *args, **kwargs):
            Racing.handed += fn is execution._run
            if fn is execution._run and Racing.handed == 5:
                os.kill(next(iter(self._processes)), signal.SIGKILL)
                while not self._broken:
                    time.sleep(0.01)
            return super().submit(fn, *args, **kwargs)

    execution.ProcessPoolExecutor = Racing
    sys.exit(main(sys.argv[1:]))
""")


def test_a_worker_killed_between_two_scenes_costs_nothing(tmp_path: Path) -> None:
    """The window in which a bench exited 1 (a BrokenProcessPool traceback) with its finished
    results in the .partial file only: a process killed after the bench last waited and
    before it handed over the next scene."""
    out = tmp_path / "a.json"
    proc = start("--count", "8", "--workers", "2", "--json", str(out), script=RACING)
    none_lost(finished(proc, out)[0], 8)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]  # no .partial


DRAWING_DIES = textwrap.dedent("""
    import os, signal, sys
    from dvqp.bench import execution
    from dvqp.cli import main
    real, parent = execution.generate_scene, os.getpid()
    def deadly(seed, index):  # the pool process drawing scene 5 dies (the OOM killer)
        if index == 5 and os.getpid() != parent:
            os.kill(os.getpid(), signal.SIGKILL)
        return real(seed, index)
    execution.generate_scene = deadly
    sys.exit(main(sys.argv[1:]))
""")


def test_a_worker_killed_while_drawing_the_scenes_costs_nothing(tmp_path: Path) -> None:
    out = tmp_path / "a.json"
    proc = start(
        "--count",
        "12",
        "--workers",
        "2",
        "--backends",
        "pinv",
        "--json",
        str(out),
        script=DRAWING_DIES,
    )
    doc, _ = finished(proc, out)
    assert indices(doc) == list(range(12))  # the same scenes: drawn here once the pool died


def interrupt(proc: subprocess.Popen[str], partial: Path) -> tuple[float, str, list[dict]]:
    """SIGINT to ``proc`` once a scene is in ``partial``: the seconds until it ended, its
    stderr, and the results that were in ``partial`` before."""
    before = scenes_in(partial, 1)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:  # the test fails; nothing of the bench is left running
        for pid in [*children(proc.pid), proc.pid]:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
        proc.communicate()
        raise
    return time.monotonic() - sent, err, before


def check_interrupted(out: Path, err: str, before: list[dict], code: int) -> None:
    assert code == 130 and "Traceback" not in err, err
    assert err.splitlines()[-1] == "dvqp: interrupted"
    doc = json.loads(out.read_text())
    assert doc["interrupted"] is True and len(doc["results"]) >= len(before)
    assert not out.with_name(out.name + ".partial").exists()


def test_ctrl_c_stops_a_pool_bench_at_once_and_keeps_what_finished(tmp_path: Path) -> None:
    out = tmp_path / "a.json"
    proc = start("--count", "40", "--workers", "2", "--json", str(out))
    took, err, before = interrupt(proc, tmp_path / "a.json.partial")
    check_interrupted(out, err, before, proc.returncode)
    print(f"SIGINT answered in {took:.2f} s")
    assert took < 5.0  # within 2 s on an idle machine
    assert children(proc.pid) == []


@pytest.fixture
def scheduler() -> Iterator[tuple[str, list[subprocess.Popen[bytes]]]]:
    """A Dask scheduler (here) and two worker processes without a nanny."""
    dd = pytest.importorskip("dask.distributed")
    with dd.LocalCluster(
        n_workers=0, processes=False, protocol="tcp", dashboard_address=None
    ) as cluster:
        address = cluster.scheduler_address
        cmd = [
            sys.executable,
            "-m",
            "distributed.cli.dask_worker",
            address,
            "--no-nanny",
            "--nthreads",
            "1",
            "--no-dashboard",
        ]
        workers = [subprocess.Popen(cmd, stderr=subprocess.DEVNULL, env=ENV) for _ in range(2)]
        try:
            with dd.Client(address) as client:
                client.wait_for_workers(2, timeout=60)
            yield address, workers
        finally:
            for worker in workers:
                worker.kill()
                worker.wait()


def test_a_dask_bench_stops_in_one_line_when_every_worker_is_gone(
    tmp_path: Path, scheduler: tuple[str, list[subprocess.Popen[bytes]]]
) -> None:
    address, workers = scheduler
    out = tmp_path / "a.json"
    proc = start("--count", "40", "--scheduler", address, "--json", str(out))
    before = scenes_in(tmp_path / "a.json.partial", 1)
    for worker in workers:
        worker.kill()
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 1 and "Traceback" not in err, err
    last = err.splitlines()[-1]
    assert last.startswith(f"dvqp: scheduler {address}: no worker left for 10 s; ")
    doc = json.loads(out.read_text())
    assert doc["interrupted"] is True and len(doc["results"]) >= len(before)


def test_ctrl_c_stops_a_dask_bench_at_once_and_keeps_what_finished(
    tmp_path: Path, scheduler: tuple[str, list[subprocess.Popen[bytes]]]
) -> None:
    out = tmp_path / "a.json"
    proc = start("--count", "40", "--scheduler", scheduler[0], "--json", str(out))
    took, err, before = interrupt(proc, tmp_path / "a.json.partial")
    check_interrupted(out, err, before, proc.returncode)
    print(f"SIGINT answered in {took:.2f} s")
    assert took < 5.0


def test_ctrl_c_stops_a_local_cluster_bench_at_once_and_keeps_what_finished(
    tmp_path: Path,
) -> None:
    out = tmp_path / "a.json"
    proc = start("--count", "40", "--scheduler", "local", "--workers", "2", "--json", str(out))
    took, err, before = interrupt(proc, tmp_path / "a.json.partial")
    check_interrupted(out, err, before, proc.returncode)
    print(f"SIGINT answered in {took:.2f} s")
    assert took < 5.0
    assert children(proc.pid) == []  # the worker processes ended with the cluster
