"""``dvqp bench`` end to end: outputs, reproducible scene files, bad input, no Dask, Ctrl-C."""

from __future__ import annotations

import argparse
import contextlib
import csv
import functools
import io
import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dvqp import load_scene, plan
from dvqp.bench import DaskUnavailableError, dask_run, execution, generate_scenes, run_suite
from dvqp.cli import main
from dvqp.cli.bench import register
from dvqp.errors import DvqpError


@functools.cache
def wired() -> bool:
    """``dvqp.cli.main`` knows the ``bench`` subcommand."""
    with contextlib.redirect_stderr(io.StringIO()) as err:
        main(["bench", "--count", "x"])
    return err.getvalue().startswith("dvqp: --count")


def bench(*argv: str) -> int:
    """``dvqp bench ARGV``: through ``dvqp.cli.main`` once it is wired in, else the same
    handling of errors (exit 2) and Ctrl-C (exit 130) around the subcommand."""
    if wired():
        return main(["bench", *argv])
    parser = argparse.ArgumentParser(prog="dvqp")
    register(parser.add_subparsers())
    args = parser.parse_args(["bench", *argv])
    try:
        return int(args.run(args))
    except DvqpError as exc:
        print(f"dvqp: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("dvqp: interrupted", file=sys.stderr)
        return 130


def strict_json(path: Path) -> dict:
    def no_nan(name: str) -> None:
        raise AssertionError(f"{name} in {path}")

    return json.loads(path.read_text(), parse_constant=no_nan)


def test_bench_prints_a_summary_and_writes_json_csv_and_scene_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "a.json"
    csv_out, scenes = str(tmp_path / "a.csv"), str(tmp_path / "s")
    code = bench(
        "--count",
        "3",
        "--seed",
        "5",
        "--backends",
        "pinv,daqp",
        "--json",
        str(out),
        "--csv",
        csv_out,
        "--save-scenes",
        scenes,
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[0].split()[:4] == ["backend", "runs", "ok", "success"]
    assert "shift 10 us" in printed and "one run at a time" in printed
    doc = strict_json(out)
    assert {"results", "summary", "machine", "versions", "seed", "count"} <= set(doc)
    assert (doc["seed"], doc["count"], doc["backends"]) == (5, 3, ["pinv", "daqp"])
    assert [(r["index"], r["backend"]) for r in doc["results"]] == [
        (i, b) for i in range(3) for b in ("pinv", "daqp")
    ]
    for r in doc["results"]:
        assert {
            "scene",
            "backend",
            "success",
            "final_tool",
            "median_step_us",
            "mean_step_us",
            "mean_solve_us",
            "parallel",
        } <= set(r)
        assert r["parallel"] is False and len(r["final_tool"]) == 4
    for figures in doc["summary"].values():
        assert {
            "success_rate",
            "failed_steps",
            "relaxed_steps",
            "step_time_sgm_ratio",
            "solve_time_sgm_ratio",
            "worst_limit_excess",
            "worst_task_error",
            "max_distance_to_qp_median_m",
        } <= set(figures)
    with open(tmp_path / "a.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 6 and rows[1]["backend"] == "daqp" and rows[1]["parallel"] == "false"
    files = sorted(p.name for p in (tmp_path / "s").iterdir())
    assert files == [f"bench-s5-000{i}.toml" for i in range(3)]
    last = doc["results"][-1]
    traj = plan(load_scene(tmp_path / "s" / files[-1]), "daqp")  # what `dvqp plan` runs
    assert [float(v) for v in traj.tool[-1]] == last["final_tool"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--backends", "pinv,nope"], "dvqp: unknown backend 'nope'"),
        (["--count", "0"], "dvqp: --count: must be an integer >= 1, got '0'"),
        (["--count", "two"], "dvqp: --count: must be an integer >= 1, got 'two'"),
        (["--workers", "0"], "dvqp: --workers: must be an integer >= 1"),
        (["--seed", "-3"], "dvqp: --seed: must be an integer >= 0"),
        (["--scene-timeout", "0"], "dvqp: --scene-timeout: must be a number of seconds > 0"),
        (["--scene-timeout", "nan"], "dvqp: --scene-timeout: must be a number of seconds > 0"),
        (["--json", "{tmp}/no/such/a.json"], "dvqp: output: "),
        (["--csv", "{tmp}/a.txt"], "dvqp: output: "),
        (["--save-scenes", "{tmp}/file.txt"], "dvqp: --save-scenes: "),
        (["--save-scenes", "{tmp}/no/such"], "dvqp: --save-scenes: "),
    ],
)
def test_bad_input_is_one_line_exit_2_and_nothing_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    (tmp_path / "file.txt").write_text("x")
    argv = [a.format(tmp=tmp_path) for a in args]
    if "--json" not in argv:
        argv += ["--json", str(tmp_path / "out.json")]
    assert bench(*argv, "--count" if "--count" not in argv else "--seed", "1") == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.startswith(message)
    assert len(captured.err.splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.txt"]


def test_without_dask_the_scheduler_option_fails_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def absent() -> None:
        raise ImportError("No module named 'dask'")

    monkeypatch.setattr(dask_run, "_load_distributed", absent)
    code = bench("--count", "2", "--scheduler", "local", "--json", str(tmp_path / "a.json"))
    assert code == 2
    assert capsys.readouterr().err == "dvqp: --scheduler needs Dask: pip install 'dvqp[dask]'\n"
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(DaskUnavailableError):
        run_suite(generate_scenes(0, 1), ["pinv"], seed=0, scheduler="local")


def test_ctrl_c_writes_the_finished_scenes_and_exits_130(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = []

    def run_then_interrupt(job: execution.Job, *args: object) -> list:
        calls.append(job.index)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(job, *args)

    real = execution.run_job
    monkeypatch.setattr(execution, "run_job", run_then_interrupt)
    out = tmp_path / "a.json"
    assert bench("--count", "4", "--backends", "pinv", "--json", str(out)) == 130
    assert capsys.readouterr().err.splitlines()[-1] == "dvqp: interrupted"
    doc = strict_json(out)
    assert doc["interrupted"] is True and [r["index"] for r in doc["results"]] == calls[:1]
    assert doc["summary"]["pinv"]["runs"] == 1 and doc["count"] == 4


def test_a_local_pool_gives_the_same_outcomes_marked_parallel(tmp_path: Path) -> None:
    from dvqp.bench import outcome_differences

    one, two = tmp_path / "one.json", tmp_path / "two.json"
    assert bench("--count", "2", "--seed", "4", "--backends", "pinv", "--json", str(one)) == 0
    assert (
        bench(
            "--count",
            "2",
            "--seed",
            "4",
            "--backends",
            "pinv",
            "--json",
            str(two),
            "--workers",
            "2",
        )
        == 0
    )
    a, b = strict_json(one), strict_json(two)
    assert outcome_differences(a["results"], b["results"]) == []
    assert b["execution"]["parallel"] is True and all(r["parallel"] for r in b["results"])


def test_the_progress_bar_is_drawn_on_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    err = Terminal()
    monkeypatch.setattr(sys, "stderr", err)
    assert bench("--count", "1", "--backends", "pinv") == 0
    assert "\r[" in err.getvalue() and "1/1" in err.getvalue()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
def test_a_real_sigint_stops_cleanly_and_keeps_what_finished(tmp_path: Path) -> None:
    if not wired():
        pytest.skip("bench is not wired into dvqp.cli.main yet")
    out, scenes = tmp_path / "a.json", tmp_path / "s"
    # the first scene's step compiled (or loaded) beforehand: on an empty cache compiling
    # takes longer than the wait below, and no scene would have finished when Ctrl-C comes
    warm = [sys.executable, "-m", "dvqp", "bench", "--count", "1", "--backends", "pinv"]
    assert subprocess.run(warm, capture_output=True, timeout=300).returncode == 0
    argv = [
        "bench",
        "--count",
        "400",
        "--backends",
        "pinv",
        "--json",
        str(out),
        "--save-scenes",
        str(scenes),
    ]
    proc = subprocess.Popen(
        [sys.executable, "-m", "dvqp", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 60.0
    while not scenes.is_dir() and time.monotonic() < deadline:  # written as the runs start
        time.sleep(0.1)
    time.sleep(2.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err
    assert err.splitlines()[-1] == "dvqp: interrupted"
    doc = strict_json(out)
    assert doc["interrupted"] is True and 1 <= len(doc["results"]) < 400
