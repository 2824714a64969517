"""dvqp export-qps: every backend call of a run as a qpsolvers problem file, with its answer.

The run: the probe JOGged 0.2 s toward a clamp 2.3 cm ahead (80 steps, braking included); its
damper stops the probe, so 32 strict problems are infeasible and their relaxed problems solved.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import qpsolvers

import dvqp
import solvers
import solvers.tiers
from dvqp.cli.main import main
from dvqp.run.qp_export import ANSWERS, INDEX
from solvers.residuals import failed_checks, kkt_residuals

SCENE = """
name = "clamp-ahead"

[pipe]
radius = 0.254
weld = 0.35

[robot]
model = "ndt13"
link_lengths = [0.334, 0.10, 0.15, 0.15, 0.15, 0.15, 0.06]
qdd_max = 10.0
q0 = [1.5708, -0.048, 0.068, 0.026, 0.08, 0.032, 0.088, -0.078, -0.088, 0.003, -0.434, 0.116,
      -0.278]

[objective]
orbital_level = 0.08
k_height = 100.0
k_obstacle = 1.0
gain = 1.0

[[obstacles]]          # a clamp on the weld, 2.3 cm ahead of the probe
center = [0.37, 0.35]
radius = 0.05
weight = 20.0

[constraints]
min_height = 0.02
margin = 0.01
influence = 0.06
damper_gain = 0.5

[motion]
dt = 0.005

[[motion.jog]]
duration = 0.2
velocity = [0.08, 0, 0, 0]
"""

X_TOLERANCE = 1e-6
"""rad/s (and slack units): how close qpsolvers' OSQP and DAQP come to the stored x. Every
problem is strictly convex (``P`` positive definite), so its minimiser is unique."""

OSQP = {"eps_abs": 1e-9, "eps_rel": 1e-9, "polish": True, "max_iter": 100000}
"""OSQP's own defaults (eps 1e-3), which qpsolvers keeps, leave errors up to 1e-2 on x."""


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("scene") / "clamp-ahead.toml"
    path.write_text(SCENE, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def exported(scene_file: Path, tmp_path_factory: pytest.TempPathFactory):
    """The export, every backend call of the same run as a watcher of plan saw it, and each
    call's inequality rows (``G``, ``h``: every fixed row of the run)."""
    scene = dvqp.load_scene(scene_file)
    seen: list[tuple[int, str, bool]] = []
    rows: list[tuple[np.ndarray, np.ndarray]] = []

    def watch(step: int, kind: str, p: solvers.Problem, s: solvers.Solution) -> None:
        seen.append((step, kind, s.found))
        rows.append((np.array(p.G), np.array(p.h)))

    dvqp.plan(scene, "daqp", watch=watch)
    folder = tmp_path_factory.mktemp("export") / "qps"
    return dvqp.export_qps(scene, "daqp", folder), seen, rows


def load(folder: Path, entry: dict) -> tuple[qpsolvers.Problem, dict[str, np.ndarray]]:
    with np.load(folder / entry["answer"]) as answer:
        return qpsolvers.Problem.load(str(folder / entry["file"])), dict(answer)


def test_every_backend_call_is_one_file_named_by_its_step_and_call(exported) -> None:
    export, seen, _ = exported
    problems = export.index["problems"]
    names, calls = [], Counter()
    for step, _, _ in seen:  # the names from the calls the watcher saw, in order
        names.append(f"clamp-ahead-{step:05d}-{calls[step]}.npz")
        calls[step] += 1
    assert [e["file"] for e in problems] == names
    assert [(e["step"], e["kind"], e["found"]) for e in problems] == seen
    on_disk = sorted(p.name for p in export.folder.iterdir() if p.suffix == ".npz")
    assert on_disk == sorted(names)
    assert sorted(p.name for p in (export.folder / ANSWERS).iterdir()) == sorted(names)
    kinds = Counter(e["kind"] for e in problems)
    assert kinds["relaxed"] >= 10 and kinds["strict"] > kinds["relaxed"]
    assert not any(p.name.startswith(".") for p in export.folder.parent.iterdir())
    traj = export.trajectory  # the run's own tally of its answers and refusals
    refused = sum(traj.refusals.values())
    assert len(problems) == traj.accuracy["solves"] + refused  # a refused strict call: 2 files
    assert sum(not e["found"] for e in problems) == refused == 32


def test_the_index_matches_the_run(exported) -> None:
    export = exported[0]
    index, traj = export.index, export.trajectory
    assert json.loads((export.folder / INDEX).read_text()) == index
    assert (index["scene"], index["backend"], index["steps"]) == ("clamp-ahead", "daqp", 80)
    assert index["error"] == "" and index["brake_start"] == traj.brake_start
    solved = {e["step"] for e in index["problems"]}
    assert solved | set(index["no_backend_call"]) == set(range(traj.n_steps))
    assert index["no_backend_call"] == [traj.n_steps - 1]  # the stop's last step: Q̇ = 0 exactly
    for e in index["problems"]:
        assert e["step_status"] == traj.status[e["step"]]
        assert e["variables"] == 13 + (4 if e["kind"] == "relaxed" else 0)
        if e["kind"] == "relaxed":  # the strict call of the same step came first, refused
            strict = index["problems"][e["solve"] - 1]
            assert (strict["step"], strict["kind"], strict["found"]) == (e["step"], "strict", False)
            assert strict["refusal"] == "infeasible" and e["step_status"] == "relaxed"


def test_a_file_keeps_the_rows_that_apply_and_the_index_maps_them_to_the_runs_rows(
    exported,
) -> None:
    export, _, rows = exported
    index = export.index
    assert index["fixed_inequalities"] == rows[0][1].shape[0] == 36
    dropped = 0
    for e, (G, h) in zip(index["problems"], rows, strict=True):
        p = qpsolvers.Problem.load(str(export.folder / e["file"]))
        kept = np.array(e["rows"], dtype=int)
        assert np.array_equal(kept, np.flatnonzero(np.isfinite(h))), e["file"]
        assert e["inequalities"] == kept.size == (0 if p.G is None else p.G.shape[0])
        if kept.size:  # bitwise the run's rows, the variables of the call's kind
            assert np.array_equal(p.G, G[kept]) and np.array_equal(p.h, h[kept])
        dropped += h.size - kept.size
    assert dropped > 1000  # most damper rows are far from their limit: 0 x <= +inf


def test_each_warm_start_is_the_previous_accepted_call_of_the_same_kind(exported) -> None:
    problems = exported[0].index["problems"]
    for i, e in enumerate(problems):
        before = [p for p in problems[:i] if p["kind"] == e["kind"]]
        expected = before[-1]["file"] if before and before[-1]["found"] else None
        assert e["warm_start"] == expected
    assert problems[0]["warm_start"] is None


def test_the_active_rows_alone_give_the_stored_answer(exported) -> None:
    """Solving with the active rows as equalities (an equality-constrained QP, by its KKT
    system) and the others dropped gives the stored x: the active set is the right one."""
    export = exported[0]
    checked = 0
    for e in export.index["problems"]:
        if not e["found"]:
            assert e["active_inequalities"] == e["active_lower"] == e["active_upper"] == []
            continue
        p, answer = load(export.folder, e)
        n = p.q.shape[0]
        eye = np.eye(n)
        active = e["active_inequalities"]
        G, h = (p.G[active], p.h[active]) if active else (np.zeros((0, n)), np.zeros(0))
        rows = [p.A, G, eye[e["active_lower"]], eye[e["active_upper"]]]
        rhs = [p.b, h, p.lb[e["active_lower"]], p.ub[e["active_upper"]]]
        C, d = np.vstack(rows), np.concatenate(rhs)
        kkt = np.block([[p.P, C.T], [C, np.zeros((C.shape[0], C.shape[0]))]])
        x = np.linalg.lstsq(kkt, np.concatenate([-p.q, d]), rcond=None)[0][:n]
        assert np.abs(x - answer["x"]).max() < X_TOLERANCE, e["file"]
        checked += 1
    assert checked > 40


def test_qpsolvers_loads_each_file_and_osqp_and_daqp_reproduce_the_answer(exported) -> None:
    export = exported[0]
    worst = {"osqp": 0.0, "daqp": 0.0}
    for e in export.index["problems"]:
        problem, answer = load(export.folder, e)
        for name, settings in (("osqp", OSQP), ("daqp", {})):
            with warnings.catch_warnings():  # qpsolvers: dense matrices handed to OSQP
                warnings.simplefilter("ignore")
                found = qpsolvers.solve_problem(problem, name, **settings)
            assert found.found == e["found"], (e["file"], name)  # refused: infeasible for both
            if e["found"]:
                worst[name] = max(worst[name], float(np.abs(found.x - answer["x"]).max()))
    assert max(worst.values()) < X_TOLERANCE, worst


def test_daqp_through_qpsolvers_gives_an_optimal_solution_by_qpsolvers_own_check(
    exported,
) -> None:
    """qpsolvers' ``Solution.is_optimal`` (primal and dual residuals and the duality gap
    ``|xᵀPx + qᵀx + bᵀy + hᵀz + …|``, which a row with ``h = +inf`` made NaN) holds for every
    problem dvqp answered; the others are infeasible for DAQP too."""
    export = exported[0]
    optimal = 0
    for e in export.index["problems"]:
        problem, _ = load(export.folder, e)
        assert problem.h is None or np.all(np.isfinite(problem.h)), e["file"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            solution = qpsolvers.solve_problem(problem, "daqp")
        assert solution.found == e["found"], e["file"]
        if e["found"]:
            assert np.isfinite(solution.duality_gap()) and solution.is_optimal(1e-9), e["file"]
            optimal += 1
    assert optimal == len(export.index["problems"]) - 32 == 79


def test_the_stored_answer_passes_solvers_residual_check_on_the_file(exported) -> None:
    export = exported[0]
    tolerance = export.index["tolerance"]
    for e in export.index["problems"]:
        p, answer = load(export.folder, e)
        assert bool(answer["found"]) == e["found"] and str(answer["kind"]) == e["kind"]
        assert str(answer["step_status"]) == e["step_status"]
        if not e["found"]:
            assert answer["x"].shape == (0,)
            continue
        problem = solvers.Problem(p.P, p.q, p.A, p.b, p.G, p.h, p.lb, p.ub)
        res, scale = kkt_residuals(problem, answer["x"], answer["y"], answer["z"], answer["z_box"])
        assert failed_checks(res, tolerance, scale) == [], e["file"]


def test_the_command_writes_the_export_and_refuses_to_overwrite_it(
    scene_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "qps"
    assert main(["export-qps", str(scene_file), "--backend", "daqp", "-o", str(out)]) == 0
    assert "of 80 steps" in capsys.readouterr().out
    written = json.loads((out / INDEX).read_text())
    assert main(["export-qps", str(scene_file), "-o", str(out)]) == 2
    assert capsys.readouterr().err.endswith(": not empty (--force replaces an earlier export)\n")
    argv = [
        "export-qps",
        str(scene_file),
        "--backend",
        "osqp",
        "-o",
        str(out),
        "--force",
        "--solver-option",
        "osqp.eps_abs=1e-7",
    ]
    assert main(argv) == 0
    again = json.loads((out / INDEX).read_text())
    assert again["backend"] == "osqp" and again["settings"] == {"eps_abs": 1e-7}
    assert len(again["problems"]) == len(list(out.glob("*.npz"))) != 0
    assert written["backend"] == "daqp"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["qps"]  # nothing else left


@pytest.mark.parametrize(
    "case",
    [
        "pinv",
        "unknown backend",
        "bad scene",
        "foreign folder",
        "a file",
        "missing parent",
        "bad setting",
    ],
)
def test_bad_input_is_one_line_exit_2_and_nothing_written(
    case: str, scene_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene, out, extra = str(scene_file), tmp_path / "qps", []
    backend = {"pinv": "pinv", "unknown backend": "nope"}.get(case, "daqp")
    if case == "bad scene":
        scene = str(tmp_path / "broken.toml")
        Path(scene).write_text("[pipe]\nradius = -1\n")
    elif case == "foreign folder":  # not an export: never replaced, even with --force
        out.mkdir()
        (out / "notes.txt").write_text("mine")
        extra = ["--force"]
    elif case == "a file":
        out.write_text("mine")
    elif case == "missing parent":
        out = tmp_path / "no" / "qps"
    elif case == "bad setting":
        extra = ["--solver-option", "daqp.no_such_setting=1"]
    before = sorted(p.name for p in tmp_path.rglob("*"))
    assert main(["export-qps", scene, "--backend", backend, "-o", str(out), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dvqp: ") and err.count("\n") == 1, err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before


def test_an_interrupted_export_leaves_nothing(scene_file: Path, tmp_path: Path) -> None:
    def interrupt(k: int, n: int) -> None:
        if k == 30:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        dvqp.export_qps(dvqp.load_scene(scene_file), "daqp", tmp_path / "qps", progress=interrupt)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("tier", ["high_accuracy", "low_accuracy"])
def test_an_export_under_a_tier_is_reproduced_within_the_tiers_tolerance(
    scene_file: Path, tmp_path: Path, tier: str
) -> None:
    pytest.importorskip("osqp")
    export = dvqp.export_qps(dvqp.load_scene(scene_file), "osqp", tmp_path / "qps", tier=tier)
    tolerance = solvers.tiers.EPS[tier]
    assert export.index["tier"] == tier and export.index["tolerance"] == tolerance
    assert export.index["settings"]["eps_abs"] == tolerance  # the tier's settings, recorded
    answered = [e for e in export.index["problems"] if e["found"]]
    assert len(answered) > 40
    for e in answered:
        problem, answer = load(export.folder, e)
        for name, settings in (("osqp", OSQP), ("daqp", {})):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = qpsolvers.solve_problem(problem, name, **settings)
            assert np.abs(found.x - answer["x"]).max() < tolerance, (e["file"], name)


def names_in(folder: Path) -> list[str]:
    """Every path under ``folder`` (hidden ones too), relative, sorted."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def export(scene_file: Path, out: object, *extra: str) -> int:
    return main(["export-qps", str(scene_file), "-o", str(out), *extra])


def test_force_replaces_only_what_the_earlier_export_wrote_or_names_what_it_would_lose(
    scene_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "qps"
    assert export(scene_file, out) == 0
    (out / "notes.txt").write_text("mine")
    (out / ANSWERS / "mine.npz").write_text("mine too")
    (out / "plots").mkdir()
    before = names_in(tmp_path)
    index = (out / INDEX).read_text()
    capsys.readouterr()
    assert export(scene_file, out, "--force", "--backend", "osqp") == 2
    assert capsys.readouterr().err == (
        f"dvqp: output: {out}: --force replaces only what an earlier export wrote; it also "
        "holds 3 other files: answers/mine.npz, notes.txt, plots/ (move them away)\n"
    )
    assert names_in(tmp_path) == before and (out / INDEX).read_text() == index
    for extra in (out / "notes.txt", out / ANSWERS / "mine.npz"):
        extra.unlink()
    (out / "plots").rmdir()
    assert export(scene_file, out, "--force", "--backend", "osqp") == 0
    assert json.loads((out / INDEX).read_text())["backend"] == "osqp"
    assert not [n for n in names_in(tmp_path) if "/." in f"/{n}"]  # nothing hidden left


def test_force_through_a_link_fills_the_linked_folder_and_keeps_link_and_folder(
    scene_file: Path, tmp_path: Path
) -> None:
    real, link = tmp_path / "qps", tmp_path / "latest"
    assert export(scene_file, real) == 0
    real.chmod(0o750)
    link.symlink_to("qps")
    inode = real.stat().st_ino
    assert export(scene_file, link, "--force", "--backend", "osqp") == 0
    assert link.is_symlink() and os.readlink(link) == "qps"
    assert real.stat().st_ino == inode and real.stat().st_mode & 0o777 == 0o750
    assert json.loads((real / INDEX).read_text())["backend"] == "osqp"
    assert sorted(os.listdir(tmp_path)) == ["latest", "qps"]


def test_force_on_a_read_only_export_is_refused_and_leaves_it(
    scene_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "qps"
    assert export(scene_file, out) == 0
    before = names_in(tmp_path)
    out.chmod(0o555)  # read-only by intent: refused even for the superuser
    capsys.readouterr()
    assert export(scene_file, out, "--force") == 2
    assert capsys.readouterr().err == f"dvqp: output: {out}: read-only: not replaced\n"
    out.chmod(0o755)
    assert names_in(tmp_path) == before


def test_dot_and_dotdot_name_the_folder_they_resolve_to(
    scene_file: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    out = tmp_path / "qps"
    out.mkdir()
    monkeypatch.chdir(out)
    assert export(scene_file, ".") == 0  # an empty folder: filled, not replaced
    assert Path.cwd() == out and (out / INDEX).is_file()  # the shell is still in it
    assert export(scene_file, ".", "--force", "--backend", "osqp") == 0
    assert json.loads((out / INDEX).read_text())["backend"] == "osqp"
    monkeypatch.chdir(tmp_path)
    assert export(scene_file, f"qps/{ANSWERS}/..", "--force") == 0
    assert json.loads((out / INDEX).read_text())["backend"] == "daqp"
    assert capsys.readouterr().out.endswith(
        "of 80 steps to qps (index.json, answers/, dvqp_qps.py)\n"
    )
    assert not [n for n in names_in(tmp_path) if "/." in f"/{n}"]  # no .old, no work folder


@pytest.mark.parametrize(
    ("index", "why"),
    [
        ('{"format": "dvqp export-qps 1", "problems": [', "index.json: not JSON ("),
        (
            '{"format": "dvqp export-qps 1", "problems": '
            '[{"file": "../x", "answer": "answers/y"}]}',
            "index.json lists '../x', not a file of the export",
        ),
        ('{"format": "other"}', "index.json is not an export's index"),
        ("[" * 100_000, "index.json: "),
    ],
    ids=["truncated", "a file outside", "another format", "nested deeply"],
)
def test_a_damaged_or_hostile_index_is_never_trusted_by_force(
    scene_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], index: str, why: str
) -> None:
    out = tmp_path / "qps"
    out.mkdir()
    (out / INDEX).write_text(index)
    (tmp_path / "x").write_text("outside")
    before = names_in(tmp_path)
    assert export(scene_file, out, "--force") == 2
    err = capsys.readouterr().err
    assert err.startswith(
        f"dvqp: output: {out}: not empty and not an export of dvqp export-qps ({why}"
    )
    assert err.endswith("): not replaced\n") and err.count("\n") == 1
    assert names_in(tmp_path) == before


def started(folder: Path, pattern: str, files: int = 10, timeout: float = 120.0) -> None:
    """Wait until a folder matching ``pattern`` in ``folder`` holds ``files`` files."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if any(len(os.listdir(w)) >= files for w in folder.glob(pattern)):
            return
        time.sleep(0.05)
    raise AssertionError(f"no {pattern} with {files} files in {folder} after {timeout} s")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
@pytest.mark.parametrize("earlier", [False, True], ids=["new folder", "over an earlier export"])
def test_sigterm_during_an_export_leaves_nothing_behind(
    scene_file: Path, tmp_path: Path, earlier: bool
) -> None:
    long = tmp_path / "long.toml"
    long.write_text(SCENE.replace("duration = 0.2", "duration = 60.0"), encoding="utf-8")
    out = tmp_path / "qps"
    if earlier:
        assert export(scene_file, out) == 0
    before = names_in(tmp_path)
    argv = [sys.executable, "-m", "dvqp", "export-qps", str(long), "-o", str(out), "--force"]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    started(out if earlier else tmp_path, ".dvqp-export.*" if earlier else ".qps.*")
    proc.send_signal(signal.SIGTERM)  # what timeout, docker stop and systemd send
    printed, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and printed == "" and err == "dvqp: terminated\n"
    assert names_in(tmp_path) == before  # the earlier export as it was, no work folder
