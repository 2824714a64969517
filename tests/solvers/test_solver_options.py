"""A QP backend's settings from the scene (``[solvers.NAME]``) and the command line
(``--solver-option NAME.KEY=VALUE``): checked before any run, handed to the backend."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import solvers
from dvqp import SceneError, load_scene, plan
from dvqp.cli import main

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def with_solvers(folder: Path, table: str, name: str = "joint-limit") -> Path:
    path = folder / f"{name}.toml"
    path.write_text((SCENES / f"{name}.toml").read_text("utf-8") + "\n" + table, "utf-8")
    return path


@pytest.mark.parametrize("name", ["osqp", "qpsolvers:osqp"])
def test_a_setting_a_backend_refuses_is_an_error_when_it_is_made(name: str) -> None:
    pytest.importorskip("osqp")
    for settings in ({"eps_abss": 1e-6}, {"linsys_solver": 3.5}, {"max_iter": "many"}):
        with pytest.raises(solvers.SolverError, match=f"^{name}: "):
            solvers.make_backend(name, **settings)
    backend = solvers.make_backend(name, eps_abs=1e-6, max_iter=50)
    assert backend.solve(solvers.Problem([[1.0]], [1.0])).found  # usable after the probe


def test_an_unknown_setting_names_the_accepted_ones() -> None:
    pytest.importorskip("osqp")
    with pytest.raises(solvers.SolverError) as caught:
        solvers.make_backend("osqp", eps_abss=1e-6)
    assert "unknown setting 'eps_abss' (accepted: " in str(caught.value)
    assert "eps_abs, " in str(caught.value)


def test_the_scene_s_settings_reach_the_backend(tmp_path: Path) -> None:
    pytest.importorskip("osqp")
    scene = load_scene(with_solvers(tmp_path, "[solvers.osqp]\nmax_iter = 1\n"))
    assert scene.solver_options == {"osqp": {"max_iter": 1}}
    capped = plan(scene, "osqp")
    assert capped.refusals.get("iteration limit", 0) > 0  # one iteration is never enough
    assert "iteration limit" not in plan(load_scene(SCENES / "joint-limit.toml"), "osqp").refusals
    # given to the call, over the scene's own: the cap lifted again
    assert "iteration limit" not in plan(scene, "osqp", options={"max_iter": 20000}).refusals


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("[solvers.osqp]\neps_abss = 1e-6\n", "solvers.osqp: osqp: unknown setting 'eps_abss'"),
        ("[solvers.osqp]\neps_abs = [1e-6]\n", "solvers.osqp.eps_abs: expected a finite number"),
        ("[solvers.osqp]\neps_abs = nan\n", "solvers.osqp.eps_abs: expected a finite number"),
        (
            "[solvers.pinv]\ngain = 1\n",
            "solvers.pinv: pinv: unknown setting 'gain'; the pseudoinverse takes: damping",
        ),
        ("[solvers.pinv]\ndamping = -1\n", "solvers.pinv: pinv: damping must be a number >= 0"),
        ("solvers = 3\n", "solvers: expected tables of settings"),
    ],
)
def test_bad_settings_in_a_scene_are_refused_at_load_naming_the_field(
    tmp_path: Path, table: str, message: str
) -> None:
    pytest.importorskip("osqp")
    path = with_solvers(tmp_path, table) if not table.startswith("solvers =") else None
    if path is None:  # a top-level key must come before the tables
        path = tmp_path / "top.toml"
        path.write_text(table + (SCENES / "joint-limit.toml").read_text("utf-8"), "utf-8")
    with pytest.raises(SceneError, match=f"^{path}: " + message.replace("[", r"\[")):
        load_scene(path)


def test_settings_of_a_backend_not_installed_are_kept_unchecked(tmp_path: Path) -> None:
    scene = load_scene(with_solvers(tmp_path, "[solvers.gurobi]\nTimeLimit = 0.1\n"))
    assert scene.solver_options == {"gurobi": {"TimeLimit": 0.1}}


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("osqp.eps_abs", "expected NAME.KEY=VALUE"),
        ("eps_abs=1e-6", "expected NAME.KEY=VALUE"),
        ("daqp.primal_tol=1e-6", "daqp is not run here (backends: osqp)"),
        ("osqp.eps_abs=[1]", "expected a finite number, a boolean or text"),
    ],
)
def test_a_bad_solver_option_is_one_line_and_exit_2_before_any_run(
    option: str, message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("osqp")
    argv = ["plan", str(SCENES / "joint-limit.toml"), "--backend", "osqp", "--solver-option"]
    assert main([*argv, option]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith(f"dvqp: --solver-option: {option!r}: {message}")


def test_solver_options_reach_plan_compare_and_bench(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("osqp")
    scene = str(SCENES / "joint-limit.toml")
    assert main(["plan", scene, "--backend", "osqp", "--solver-option", "osqp.max_iter=1"]) == 0
    assert "iteration limit" in capsys.readouterr().out
    assert main(["compare", scene, "--backends", "osqp", "--solver-option", "osqp.eps_abss=1"]) == 2
    assert "unknown setting 'eps_abss'" in capsys.readouterr().err
    out = tmp_path / "bench.json"
    assert (
        main(
            [
                "bench",
                "--count",
                "2",
                "--backends",
                "osqp",
                "--json",
                str(out),
                "--solver-option",
                "osqp.max_iter=1",
            ]
        )
        == 0
    )
    summary = json.loads(out.read_text("utf-8"))["summary"]["osqp"]
    assert summary["capped_calls"] > 0 and "capped calls" in capsys.readouterr().out


def refused_setting(folder: Path, capfd: pytest.CaptureFixture[str], option: str) -> str:
    """``plan --backend osqp --solver-option OPTION``: exit 2, nothing on the file descriptor
    1 (C output included), one line on stderr; the line."""
    pytest.importorskip("osqp")
    scene = with_solvers(folder, "")
    assert main(["plan", str(scene), "--backend", "osqp", "--solver-option", option]) == 2
    out, err = capfd.readouterr()
    assert out == "" and err.count("\n") == 1
    return err.rstrip("\n")


def test_a_wrongly_typed_setting_is_refused_with_the_whole_message(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    err = refused_setting(tmp_path, capfd, "osqp.max_iter=abc")
    assert err.startswith("dvqp: osqp: settings max_iter refused: osqp: adapter error: TypeError: ")
    # the message pybind11 spreads over lines, whole: the types it takes and what it was given
    assert "The following argument types are supported: 1. (" in err
    assert "Invoked with: " in err and err.endswith("'abc'")


def test_a_setting_out_of_its_range_says_osqps_own_reason_on_stderr(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    err = refused_setting(tmp_path, capfd, "osqp.eps_abs=-1")  # OSQP prints it, to stdout
    assert err == (
        "dvqp: osqp: settings eps_abs refused: ERROR in validate_settings: eps_abs must be "
        "nonnegative; ERROR in osqp_setup: Solver settings validation. (osqp raised "
        "OSQPException: 2)"
    )


def test_the_baseline_takes_its_damping_from_the_options_and_the_command_line() -> None:
    scene = load_scene(SCENES / "joint-limit.toml")
    plain, damped = plan(scene, "pinv"), plan(scene, "pinv", options={"damping": 0.05})
    assert plain.success.all() and damped.success.all()
    assert np.abs(plain.q - damped.q).max() > 1e-6  # the damped inverse, not eq. 18's
    scene_file = str(SCENES / "joint-limit.toml")
    assert (
        main(["plan", scene_file, "--backend", "pinv", "--solver-option", "pinv.damping=0.05"]) == 1
    )
