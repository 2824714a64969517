"""``dvqp plan --retime``: the summary line, the file written, the refusals."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from dvqp.cli import main
from tests.cli.test_cli import FAR, no_traceback, write_scene
from tests.runs import SCENES

pytest.importorskip("toppra")

PAPER = str(SCENES / "paper-two-inlets.toml")


def test_plan_retime_prints_both_durations_and_writes_the_joint_trajectory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "paper.jt.json"
    assert main(["plan", PAPER, "--retime", "--rate", "250", "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    found = re.fullmatch(
        r"retimed         (\d+\.\d\d) s \(planned 3\.80 s\), (\d+) samples at "
        r"250 Hz, limits kept",
        lines[-2],
    )
    assert found, lines[-2]
    assert lines[-1] == f"saved           {out}"
    points = json.loads(out.read_text(encoding="utf-8"))["points"]
    assert len(points) == int(found[2])
    last = points[-1]["time_from_start"]
    assert last["sec"] + 1e-9 * last["nanosec"] == pytest.approx(float(found[1]), abs=0.005)
    assert points[1]["time_from_start"] == {"sec": 0, "nanosec": 4_000_000}  # 250 Hz


def test_plan_retime_writes_csv_and_npz_by_suffix(tmp_path: Path) -> None:
    scene = write_scene(tmp_path)
    assert main(["plan", scene, "--retime", "-o", str(tmp_path / "r.csv")]) == 0
    table = np.loadtxt(tmp_path / "r.csv", delimiter=",", skiprows=1)
    assert table.shape[1] == 1 + 3 * 13 and np.allclose(np.diff(table[:, 0]), 0.002)
    assert main(["plan", scene, "--retime", "-o", str(tmp_path / "r.npz")]) == 0
    with np.load(tmp_path / "r.npz") as data:
        assert np.array_equal(data["t"], table[:, 0]) and data["qddot"].shape == (len(table), 13)


def test_plot_of_a_retimed_file_says_what_it_is_and_what_to_plot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene, npz = write_scene(tmp_path), tmp_path / "r.npz"
    assert main(["plan", scene, "--retime", "-o", str(npz)]) == 0
    capsys.readouterr()
    assert main(["plot", str(npz), "-o", str(tmp_path / "r.png")]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"dvqp: {npz}: a retimed motion (dvqp plan --retime): dvqp plot draws "
        "planned runs; save the run itself (dvqp plan SCENE -o RUN.npz) and plot "
        "that\n"
    )
    assert not (tmp_path / "r.png").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--retime", "--rate", "0"], "dvqp: --rate: must be > 0, got 0.0"),
        (["--retime", "--rate", "-3"], "dvqp: --rate: must be > 0, got -3.0"),
        (["--rate", "100"], "dvqp: --rate: is the rate of --retime: give --retime too"),
        (
            ["--retime", "-o", "{dir}/x.txt"],
            "dvqp: output: {dir}/x.txt: unknown format '.txt' (use .npz, .csv, .json)",
        ),
        (
            ["-o", "{dir}/x.json"],
            "dvqp: output: {dir}/x.json: unknown format '.json' (use .npz, .csv)",
        ),
    ],
)
def test_plan_retime_refuses_bad_input_before_the_run_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    argv = [a.format(dir=tmp_path) for a in args]
    assert main(["plan", write_scene(tmp_path), *argv]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == message.format(dir=tmp_path) + "\n"
    assert no_traceback(captured.err) and list(tmp_path.iterdir()) == [tmp_path / "small.toml"]


def test_plan_retime_of_a_failed_run_retimes_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, "far", motion=FAR)
    out = tmp_path / "far.jt.json"
    assert main(["plan", scene, "--retime", "-o", str(out)]) == 1
    captured = capsys.readouterr()
    assert "retimed" not in captured.out and not out.exists()
    assert captured.err.startswith("dvqp: ") and "target not reached" in captured.err


def test_plan_retime_without_toppra_says_how_to_install_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(__import__("sys").modules, "toppra", None)
    assert main(["plan", write_scene(tmp_path), "--retime", "-o", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    assert no_traceback(err) and err.endswith("pip install 'dvqp[retime]'\n")
    assert not (tmp_path / "r.csv").exists()


def test_a_rate_too_low_for_the_path_is_warned_of_on_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "slow.jt.json"
    assert main(["plan", PAPER, "--retime", "--rate", "0.01", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    assert "2 samples at 0.01 Hz, limits kept" in captured.out
    assert captured.err == (
        f"dvqp: warning: {PAPER}: retimed at 0.01 Hz, its 2 samples trace 31% of the planned "
        "path (a controller going straight from one to the next leaves it): use a higher "
        "--rate\n"
    )
    assert len(json.loads(out.read_text(encoding="utf-8"))["points"]) == 2  # written all the same
    assert main(["plan", PAPER, "--retime", "--rate", "20", "-o", str(out)]) == 0
    assert capsys.readouterr().err == ""  # 26 samples trace the path
