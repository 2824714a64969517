"""The ``dvqp`` command line end to end: exit codes, files written (or not), outputs."""

from __future__ import annotations

import errno
import io
import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from dvqp import Trajectory
from dvqp.cli import main
from dvqp.resolution.registry import available_resolvers
from tests.common import Q0

SCENE = """
name = "{name}"
[pipe]
radius = 0.254
weld = 0.35
[robot]
model = "ndt13"
link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
q0 = {q0}
[objective]
orbital_level = 0.08
[[obstacles]]
center = [0.20, 0.48]
radius = {radius}
[motion]
dt = 0.005
ramp = 0.0
{motion}
"""
JOG = "[[motion.jog]]\nduration = 0.1\nvelocity = [0.05, 0.0, 0.0, 0.0]"
FAR = "[motion.path]\nwaypoints = [[0.30, 0.35, 0.082, 0.0], [0.30, 1.20, 0.082, 0.0]]\nspeed = 4.0"


def write_scene(folder: Path, name: str = "small", radius: float = 0.07, motion: str = JOG) -> str:
    path = folder / f"{name}.toml"
    text = SCENE.format(name=name, radius=radius, motion=motion, q0=Q0)
    path.write_text(text, encoding="utf-8")
    return str(path)


def no_traceback(text: str) -> bool:
    return "Traceback" not in text and all(line.startswith("dvqp: ") for line in text.splitlines())


def test_plan_writes_the_trajectory_and_prints_a_summary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path)
    out = tmp_path / "traj.npz"
    assert main(["plan", scene, "--backend", "pinv", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    labels = [
        "steps           21: 21 optimal, 0 relaxed, 0 failed",
        "result          safe to send: every limit kept",
        "max task error",
        "min clearance",
        "step time       median",
        "final tool DV   l = 0.3023 m",
        "end             at rest after 0.005 s of braking (1 step)",
        f"saved           {out}",
    ]
    for label in labels:
        assert label in captured.out
    assert captured.err == ""
    traj = Trajectory.load(out)
    assert traj.n_steps == 21 and traj.backend == "pinv" and "small" in traj.scene_text
    assert traj.brake_start == 20 and not traj.qdot[-1].any()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml", "traj.npz"]


def test_plan_writes_csv_by_suffix(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "traj.csv"
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(out)]) == 0
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table.shape == (22, 1 + 13 + 13 + 4 + 4)  # t, q, qdot, tool, tracking error


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--backend", "nope"], "dvqp: unknown backend 'nope'; installed: pinv, "),
        (
            ["--backend", "pinv", "-o", "{tmp}/traj.txt"],
            "dvqp: output: {tmp}/traj.txt: unknown format '.txt' (use .npz, .csv)",
        ),
        (["--backend", "pinv", "-o", "{tmp}/no/traj.npz"], "dvqp: output: {tmp}/no: no such dir"),
    ],
    ids=["unknown backend", "unknown suffix", "missing folder"],
)
def test_plan_rejects_bad_arguments_with_exit_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    scene = write_scene(tmp_path)
    args = [a.format(tmp=tmp_path) for a in args]
    assert main(["plan", scene, *args]) == 2
    captured = capsys.readouterr()
    assert captured.err.startswith(message.format(tmp=tmp_path))
    assert captured.err.count("\n") == 1 and no_traceback(captured.err) and captured.out == ""
    assert [p.name for p in tmp_path.iterdir()] == ["small.toml"]


def test_plan_of_an_invalid_scene_exits_2_naming_file_and_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, radius=-0.07)
    out = tmp_path / "traj.npz"
    assert main(["plan", scene, "-o", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"dvqp: {scene}: obstacles[0].radius: must be > 0, got -0.07\n"
    assert not out.exists() and captured.out == ""


def test_plan_of_an_unreachable_path_exits_1_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    scene = write_scene(tmp_path, motion=FAR)
    out = tmp_path / "traj.npz"
    assert main(["plan", scene, "--backend", "daqp", "-o", str(out)]) == 1
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and no_traceback(captured.err)
    # the path ends at 0.215 s, at 1.5 rad/s: the stop takes 42 or 43 steps, the tool held
    # first: Q̇ = 0 becomes feasible at the edge, where answers ~3e-14 rad/s apart (rows that
    # do not apply shown to the solver or not; clearances within their 10 µm) fall either side
    head = f"dvqp: {scene}: daqp: target not reached at t = "
    assert lines[0].startswith(head)
    assert lines[0][len(head) :].startswith(("0.425 s: ", "0.430 s: "))
    assert out.exists()  # the failed run is kept, to look at
    assert "final deviation" in captured.out


def test_compare_prints_one_table_and_writes_json_and_csv(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    scenes = [write_scene(tmp_path, "one"), write_scene(tmp_path, "two", radius=0.05)]
    js, cs = tmp_path / "cmp.json", tmp_path / "cmp.csv"
    code = main(
        [
            "compare",
            *scenes,
            "--backends",
            "pinv,daqp",
            "--json",
            str(js),
            "--csv",
            str(cs),
            "--wide",
        ]
    )
    assert code == 0
    captured = capsys.readouterr()
    lines = captured.out.splitlines()
    assert lines[0].split() == [
        "scene",
        "backend",
        "ok",
        "tracked",
        "steps",
        "med",
        "us",
        "p95",
        "us",
        "solver",
        "us",
        "rest",
        "us",
        "iters",
        "x",
        "pinv",
        "task",
        "err",
        "clearance",
        "m",
        "closest",
        "self",
        "m",
        "qdd",
        "excess",
        "q",
        "viol",
        "rad",
        "qd",
        "viol",
        "rad/s",
        "slowed",
        "relaxed",
        "path",
        "dev",
        "m",
        "refused",
        "r_prim",
        "r_dual",
        "gap",
        "split",
        "fails",
        "end",
        "qd",
        "brake",
        "s",
        "levels",
        "gave",
        "way",
        "least",
        "squares",
    ]
    assert [line.split()[:5] for line in lines[2:6]] == [
        ["one", "pinv", "yes", "yes", "21"],
        ["one", "daqp", "yes", "yes", "23"],
        ["two", "pinv", "yes", "yes", "21"],
        ["two", "daqp", "yes", "yes", "23"],
    ]
    assert no_traceback(captured.err)
    doc = json.loads(js.read_text(encoding="utf-8"), parse_constant=pytest.fail)  # no NaN/inf
    assert set(doc["machine"]) == {"platform", "processor", "cpu_count", "python"}
    assert {"dvqp", "numpy", "pinocchio", "daqp"} <= set(doc["versions"])
    assert doc["backends"] == ["pinv", "daqp"] and len(doc["results"]) == 4
    first = doc["results"][0]
    assert first["ratio_to_pinv"] == 1.0 and first["success"] is True and first["steps"] == 21
    keys = [
        "median_step_us",
        "p95_step_us",
        "max_task_error",
        "min_clearance",
        "min_probe_clearance",
        "min_tilt",
        "max_limit_excess",
        "max_joint_limit_violation",
        "max_velocity_limit_violation",
        "failures",
        "relaxed",
        "substepped",
        "braking_time",
        "refused_calls",
    ]
    for key in keys:
        assert isinstance(first[key], (int, float)), key
    assert [r["final_joint_speed"] for r in doc["results"]] == [0.0] * 4  # every run at rest
    assert [r["braking_time"] for r in doc["results"]] == pytest.approx([0.005, 0.015] * 2)
    header = cs.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert header[:3] == ["scene", "file", "backend"] and "ratio_to_pinv" in header


def test_compare_draws_its_figure(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    scenes = [write_scene(tmp_path, "one"), write_scene(tmp_path, "two")]
    fig = tmp_path / "cmp.png"
    assert main(["compare", *scenes, "--backends", "pinv", "--plot", str(fig)]) == 0
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and fig.stat().st_size > 10_000
    assert (
        main(["compare", scenes[0], "--backends", "pinv", "--plot", str(tmp_path / "x.gif")]) == 2
    )
    assert "unknown format '.gif'" in capsys.readouterr().err


def test_compare_runs_scenes_in_parallel_processes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scenes = [write_scene(tmp_path, "one"), write_scene(tmp_path, "two")]
    assert main(["compare", *scenes, "--backends", "pinv", "--jobs", "2"]) == 0
    rows = capsys.readouterr().out.splitlines()[2:]
    assert [r.split()[0] for r in rows] == ["one", "two"]


def test_compare_reports_a_failed_run_in_its_table_and_exits_1_only_when_strict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("daqp")
    scene = write_scene(tmp_path, "far", motion=FAR)
    assert main(["compare", scene, "--backends", "daqp"]) == 0  # the comparison ran
    out = capsys.readouterr().out
    assert out.splitlines()[2].split()[:3] == ["far", "daqp", "NO"]
    said = " ".join(out.split())  # the footer is wrapped to 100 columns
    assert "far / daqp: " in said and "target not reached" in said
    assert main(["compare", scene, "--backends", "daqp", "--check"]) == 1
    assert main(["compare", write_scene(tmp_path), "--backends", "daqp", "--check"]) == 0


def test_compare_with_an_invalid_scene_exits_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    good, bad = write_scene(tmp_path, "good"), write_scene(tmp_path, "bad", radius=0.0)
    js = tmp_path / "cmp.json"
    assert main(["compare", good, bad, "--backends", "pinv", "--json", str(js)]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"dvqp: {bad}: obstacles[0].radius: must be > 0, got 0.0\n"
    assert not js.exists() and captured.out == ""
    assert main(["compare", good, "--backends", "pinv,nope"]) == 2
    assert "unknown backend 'nope'" in capsys.readouterr().err


def test_compare_draws_a_progress_bar_on_a_terminal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    term = Terminal()
    monkeypatch.setattr("sys.stderr", term)
    assert main(["compare", write_scene(tmp_path), "--backends", "pinv"]) == 0
    assert "[##############################] 1/1" in term.getvalue()
    assert term.getvalue().endswith("\r")  # erased at the end
    assert "Traceback" not in term.getvalue()


def test_plot_draws_a_saved_trajectory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("matplotlib")
    out = tmp_path / "traj.npz"
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(out)]) == 0
    png, gif = tmp_path / "fig.png", tmp_path / "anim.gif"
    assert main(["plot", str(out), "-o", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
    assert main(["plot", str(out), "-o", str(gif), "--gif"]) == 0
    assert gif.read_bytes()[:3] == b"GIF"
    assert main(["plot", str(tmp_path / "small.toml"), "-o", str(png)]) == 2
    assert "not a dvqp trajectory" in capsys.readouterr().err


def test_backends_lists_pinv_and_the_installed_solvers(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["backends"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("pinv ") and "dvqp" in lines[0]
    assert lines[0].endswith("(pseudoinverse baseline, paper eq. 18)")
    assert [line.split()[0] for line in lines] == available_resolvers()
    assert any(line.split()[0] == "osqp" and line.split()[1] == "osqp" for line in lines)
    for line in lines:
        generic = line.startswith("qpsolvers:")
        assert generic <= (" via qpsolvers " in line), line


def test_usage_errors_exit_2_and_help_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([]) == 2
    assert main(["plan"]) == 2
    assert main(["compare", "x.toml", "--jobs", "0"]) == 2
    assert main(["--help"]) == 0
    assert "plan" in capsys.readouterr().out


def test_version_prints_the_package_version(capsys: pytest.CaptureFixture[str]) -> None:
    from dvqp import __version__

    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"dvqp {__version__}\n"


def test_an_output_that_is_a_directory_exits_2_before_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path)
    (tmp_path / "out.npz").mkdir()
    assert main(["plan", scene, "--backend", "pinv", "-o", str(tmp_path / "out.npz")]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"dvqp: output: {tmp_path / 'out.npz'}: is a directory\n"
    assert captured.out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.npz", "small.toml"]


@pytest.mark.parametrize("suffix", [".npz", ".csv"])
def test_a_full_disk_while_saving_is_one_line_and_leaves_nothing(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    suffix: str,
) -> None:
    def full(fh, *args: object, **kwargs: object) -> None:  # type: ignore[no-untyped-def]
        fh.write(b"half a file")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("dvqp.motion.trajectory.np.savez_compressed", full)
    monkeypatch.setattr("dvqp.motion.trajectory.np.savetxt", full)
    out = tmp_path / f"traj{suffix}"
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"dvqp: output: {out}: cannot write: No space left on device\n"
    assert [p.name for p in tmp_path.iterdir()] == ["small.toml"]  # no temporary file either


def test_plot_of_a_missing_or_foreign_file_says_so_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "fig.png"
    pickled = tmp_path / "objects.npz"
    np.savez(pickled, t=np.array([{"a": 1}], dtype=object))
    shapes = tmp_path / "shapes.npz"
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(shapes)]) == 0
    with np.load(shapes) as data:
        arrays = {key: data[key] for key in data.files}
    np.savez(shapes, **{**arrays, "tool": arrays["tool"][:, :2]})
    heights = tmp_path / "heights.npz"  # the link chords' heights without the holder's
    np.savez(heights, **{**arrays, "holder_height": np.zeros(0)})
    capsys.readouterr()
    cases = {
        tmp_path / "missing.npz": "cannot read: No such file or directory",
        tmp_path / "small.toml": "not a dvqp trajectory (not an .npz file)",
        pickled: "not a dvqp trajectory (member 't': pickled Python objects are not read)",
        shapes: "not a dvqp trajectory (arrays of unexpected shapes)",
        heights: "not a dvqp trajectory (arrays of unexpected shapes)",
    }
    for path, reason in cases.items():
        assert main(["plot", str(path), "-o", str(png)]) == 2
        assert capsys.readouterr().err == f"dvqp: {path}: {reason}\n"
    assert not png.exists()


def test_ctrl_c_in_a_run_exits_130_with_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(sys.modules["dvqp.cli.main"], "plan", interrupted)
    out = tmp_path / "traj.npz"
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(out)]) == 130
    assert capsys.readouterr() == ("", "dvqp: interrupted\n")
    assert [p.name for p in tmp_path.iterdir()] == ["small.toml"]


def test_ctrl_c_while_saving_leaves_no_half_written_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def interrupted(fh, *args: object, **kwargs: object) -> None:  # type: ignore[no-untyped-def]
        fh.write(b"half a file")
        raise KeyboardInterrupt

    monkeypatch.setattr("dvqp.motion.trajectory.np.savez_compressed", interrupted)
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(tmp_path / "t.npz")])
    assert capsys.readouterr().err == "dvqp: interrupted\n"
    assert [p.name for p in tmp_path.iterdir()] == ["small.toml"]


LONG = "[[motion.jog]]\nduration = 7500.0\nvelocity = [0.0, 0.0, 0.0, 0.0]"  # 1.5e6 steps


@pytest.mark.parametrize(
    ("signum", "code", "said"),
    [(signal.SIGINT, 130, "dvqp: interrupted"), (signal.SIGTERM, 143, "dvqp: terminated")],
    ids=["SIGINT", "SIGTERM"],
)
@pytest.mark.parametrize(
    "args",
    [
        ["plan", "{scene}", "--backend", "pinv", "-o", "{tmp}/t.npz"],
        [
            "compare",
            "{scene}",
            "{tmp}/two.toml",
            "--backends",
            "pinv,daqp",
            "--jobs",
            "2",
            "--json",
            "{tmp}/c.json",
        ],
    ],
    ids=["plan", "compare --jobs 2"],
)
@pytest.mark.skipif(
    not sys.platform.startswith("linux"), reason="workers are forked (inherit the handler) on Linux"
)
def test_a_real_sigint_or_sigterm_stops_cleanly_with_one_line(
    tmp_path: Path, args: list[str], signum: int, code: int, said: str
) -> None:
    scene = write_scene(tmp_path, motion=LONG)
    write_scene(tmp_path, "two", motion=LONG)
    argv = [a.format(scene=scene, tmp=tmp_path) for a in args]
    proc = subprocess.Popen(
        [sys.executable, "-m", "dvqp", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    note = proc.stderr.readline()  # announced before the run starts
    assert note.startswith(f"dvqp: note: {scene}: about 1.5e+06 steps"), note
    time.sleep(0.3)
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == code and out == ""
    assert err.splitlines()[-1] == said and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml", "two.toml"]


def test_a_run_too_big_for_the_memory_is_refused_before_it_starts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("dvqp.cli.progress.physical_memory", lambda: 100_000_000)
    scene = write_scene(tmp_path, motion=LONG)
    assert main(["plan", scene, "--backend", "pinv", "-o", str(tmp_path / "t.npz")]) == 2
    assert capsys.readouterr().err == (
        f"dvqp: {scene}: motion: about 1.5e+06 steps (2.1 h of motion in steps of 0.005 s): "
        "roughly 2.5 min and 1.7 GB, more than this machine's 0.1 GB allow: use a larger dt or "
        "a shorter motion\n"
    )
    assert [p.name for p in tmp_path.iterdir()] == ["small.toml"]


def test_numerical_warnings_are_summed_up_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from dvqp import plan

    def noisy(*args: object, **kwargs: object) -> Trajectory:
        for _ in range(17):
            np.float64(1e308) * np.float64(10.0)
        return plan(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(sys.modules["dvqp.cli.main"], "plan", noisy)
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv"]) == 0
    assert capsys.readouterr().err == (  # once per place in the code
        "dvqp: warning: RuntimeWarning: overflow encountered in scalar multiply\n"
    )


def test_the_progress_bar_tells_the_time_left(monkeypatch: pytest.MonkeyPatch) -> None:
    from dvqp.cli.progress import ProgressBar, duration

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    clock = iter([0.0, 30.0, 60.0])
    monkeypatch.setattr("dvqp.cli.progress.time.perf_counter", lambda: next(clock))
    term = Terminal()
    bar = ProgressBar(term)  # started at t = 0
    bar.show(1, 4, "steps")  # 30 s for a quarter: 1.5 min left
    bar.show(3, 4, "steps")  # 60 s for three quarters: 20 s left
    frames = term.getvalue().split("\r")[1:]
    assert frames[0].startswith("[#######.......................] 1/4 1.5 min left steps")
    assert frames[1].startswith("[######################........] 3/4 20 s left steps")
    assert [duration(s) for s in (42, 210, 4680, 9000)] == ["42 s", "3.5 min", "78 min", "2.5 h"]


def test_the_time_left_counts_from_the_first_step_not_from_compiling(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from dvqp.cli.progress import ProgressBar

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    clock = iter([0.0, 1.5, 20.0, 20.0, 30.0])
    monkeypatch.setattr("dvqp.cli.progress.time.perf_counter", lambda: next(clock))
    term = Terminal()
    bar = ProgressBar(term)  # started at t = 0
    bar.show(0, 1, "compiling")  # t = 1.5
    bar.note("compiled in 20 s")  # a line of its own
    bar.show(1, 11, "steps")  # t = 20: the steps' clock starts here, at step 1
    bar.show(6, 11, "steps")  # t = 30: 10 s for 5 steps, 5 more: 10 s left (not 40)
    text = term.getvalue()
    assert "dvqp: compiled in 20 s\n" in text
    assert text.split("\r")[-1].startswith("[################..............] 6/11 10 s left")


def test_a_quiet_worker_ends_on_ctrl_c_without_a_word() -> None:
    code = (
        "import os, signal, time\n"
        "from dvqp.run.comparison import quiet_worker\n"
        "quiet_worker()\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "time.sleep(5)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert (done.returncode, done.stdout, done.stderr) == (130, "", "")
