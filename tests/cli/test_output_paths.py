"""Every command that writes checks its output first: the name resolved (empty, ``.``, ``..``,
symbolic links, a folder, a missing or read-only place) and refused in one line, exit 2,
before the command reads its input or runs anything; a good name behind a symbolic link is
written through the link."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from dvqp import Trajectory
from dvqp.cli import main
from tests.cli.test_cli import write_scene

COMMANDS = {  # argv ({input}: a file that does not exist; {out}: the output) and its suffix
    "plan": (["plan", "{input}.toml", "--backend", "pinv", "-o", "{out}"], ".npz"),
    "plan --retime": (["plan", "{input}.toml", "--retime", "-o", "{out}"], ".json"),
    "compare --json": (["compare", "{input}.toml", "--json", "{out}"], ".json"),
    "compare --csv": (["compare", "{input}.toml", "--csv", "{out}"], ".csv"),
    "compare --plot": (["compare", "{input}.toml", "--plot", "{out}"], ".png"),
    "plot": (["plot", "{input}.npz", "-o", "{out}"], ".png"),
    "plot --gif": (["plot", "{input}.npz", "--gif", "-o", "{out}"], ".gif"),
    "plot --limits": (["plot", "{input}.npz", "--limits", "-o", "{out}"], ".png"),
    "plot --3d": (["plot", "{input}.npz", "--3d", "-o", "{out}"], ".png"),
    "bench --json": (["bench", "--count", "1", "--json", "{out}"], ".json"),
    "bench --csv": (["bench", "--count", "1", "--csv", "{out}"], ".csv"),
    "export-qps": (["export-qps", "{input}.toml", "-o", "{out}"], ""),
}


def refused(tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, out: str) -> str:
    """Run ``command`` writing ``out``; check it exits 2 with one line, printing and writing
    nothing; return the line."""
    argv, _ = COMMANDS[command]
    before = sorted(os.listdir(tmp_path))
    code = main([a.format(input=tmp_path / "missing", out=out) for a in argv])
    captured = capsys.readouterr()
    assert code == 2 and captured.out == "", captured
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err
    assert sorted(os.listdir(tmp_path)) == before  # nothing written, no temporary file
    return captured.err.rstrip("\n")


@pytest.mark.parametrize("command", COMMANDS)
def test_an_empty_output_name_is_refused_before_the_input_is_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    assert refused(tmp_path, capsys, command, "") == "dvqp: output: empty file name"
    assert refused(tmp_path, capsys, command, "  ") == "dvqp: output: empty file name"


@pytest.mark.parametrize("command", COMMANDS)
def test_an_output_in_a_missing_folder_is_refused_before_the_input_is_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    suffix = COMMANDS[command][1]
    out = f"{tmp_path}/no/such/out{suffix}"
    assert (
        refused(tmp_path, capsys, command, out)
        == f"dvqp: output: {tmp_path}/no/such: no such directory"
    )
    (tmp_path / "file").write_text("mine")
    out = f"{tmp_path}/file/out{suffix}"
    assert (
        refused(tmp_path, capsys, command, out) == f"dvqp: output: {tmp_path}/file: not a directory"
    )
    assert (tmp_path / "file").read_text() == "mine"


@pytest.mark.parametrize("command", [c for c in COMMANDS if COMMANDS[c][1]])
@pytest.mark.parametrize("name", [".", "..", "sub/..", "sub/.", "sub/", "sub", "to-sub"])
def test_a_file_output_that_names_a_folder_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    command: str,
    name: str,
) -> None:
    (tmp_path / "sub").mkdir()
    (tmp_path / "to-sub").symlink_to("sub")
    monkeypatch.chdir(tmp_path)
    assert refused(tmp_path, capsys, command, name) == f"dvqp: output: {Path(name)}: is a directory"


@pytest.mark.parametrize("command", [c for c in COMMANDS if COMMANDS[c][1]])
def test_a_file_output_that_cannot_be_replaced_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    suffix = COMMANDS[command][1]
    loop = tmp_path / f"loop{suffix}"
    loop.symlink_to(loop.name)
    assert (
        refused(tmp_path, capsys, command, str(loop)) == f"dvqp: output: {loop}: symbolic link loop"
    )
    device = tmp_path / f"null{suffix}"
    device.symlink_to(os.devnull)
    expected = f"dvqp: output: {device}: not a regular file: not replaced"
    assert refused(tmp_path, capsys, command, str(device)) == expected
    kept = tmp_path / f"kept{suffix}"
    kept.write_text("mine")
    kept.chmod(0o444)  # read-only by intent: refused even for the superuser
    assert (
        refused(tmp_path, capsys, command, str(kept))
        == f"dvqp: output: {kept}: read-only: not replaced"
    )
    assert kept.read_text() == "mine"


@pytest.mark.skipif(not Path("/proc/self").exists(), reason="needs /proc")
@pytest.mark.parametrize("command", COMMANDS)
def test_an_output_where_nothing_can_be_written_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    out = f"/proc/out{COMMANDS[command][1]}"
    assert refused(tmp_path, capsys, command, out).startswith(
        "dvqp: output: /proc: cannot write here ("
    )


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda d: (d / "out").write_text("mine"), "{out}: not a folder"),
        (lambda d: (d / "out").symlink_to("out"), "{out}: symbolic link loop"),
        (
            lambda d: ((d / "out").mkdir(), (d / "out").chmod(0o555)),
            "{out}: read-only: not replaced",
        ),
        (
            lambda d: ((d / "out").mkdir(), (d / "out" / "x").touch()),
            "{out}: not empty (--force replaces an earlier export)",
        ),
    ],
    ids=["a file", "a link loop", "a read-only folder", "a folder of other files"],
)
def test_a_folder_output_that_cannot_take_the_export_is_refused(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    make,
    message: str,  # type: ignore[no-untyped-def]
) -> None:
    make(tmp_path)
    out = tmp_path / "out"
    assert refused(tmp_path, capsys, "export-qps", str(out)) == "dvqp: output: " + message.format(
        out=out
    )


def test_bench_checks_its_scene_folder_as_an_output_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "file").write_text("mine")
    for folder, reason in [
        ("", "empty file name"),
        (f"{tmp_path}/file", f"{tmp_path}/file: not a folder"),
        (f"{tmp_path}/no/such", f"{tmp_path}/no: no such directory"),
    ]:
        assert main(["bench", "--count", "1", "--save-scenes", folder]) == 2
        assert capsys.readouterr().err == f"dvqp: --save-scenes: {reason}\n"
    assert os.listdir(tmp_path) == ["file"]


def test_a_trajectory_written_through_a_symbolic_link_keeps_the_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "runs").mkdir()
    (tmp_path / "runs" / "old.npz").write_text("an older run")
    link = tmp_path / "latest.npz"
    link.symlink_to(Path("runs") / "old.npz")
    assert main(["plan", write_scene(tmp_path), "--backend", "pinv", "-o", str(link)]) == 0
    assert f"saved           {link}" in capsys.readouterr().out
    assert link.is_symlink() and os.readlink(link) == str(Path("runs") / "old.npz")
    assert Trajectory.load(tmp_path / "runs" / "old.npz").backend == "pinv"
    assert sorted(os.listdir(tmp_path / "runs")) == ["old.npz"]  # no temporary file left
