"""``--backends LIST`` of ``compare`` and ``bench``: an empty list or an empty name is refused
in one line before anything runs (it ran every backend)."""

from __future__ import annotations

from pathlib import Path

import pytest

from dvqp.cli import main
from tests.cli.test_cli import write_scene

EMPTY = "dvqp: --backends: empty list: name at least one backend (dvqp backends lists them)\n"


@pytest.mark.parametrize("command", ["compare", "bench"])
@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", EMPTY),
        (" , ", EMPTY),
        ("pinv,,daqp", "dvqp: --backends: 'pinv,,daqp': an empty name\n"),
        ("pinv,", "dvqp: --backends: 'pinv,': an empty name\n"),
    ],
    ids=["empty", "blank names", "an empty name", "a trailing comma"],
)
def test_an_empty_backend_list_or_name_is_refused_before_anything_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, text: str, message: str
) -> None:
    out = tmp_path / "out.json"
    given = [write_scene(tmp_path)] if command == "compare" else ["--count", "1"]
    assert main([command, *given, "--backends", text, "--json", str(out)]) == 2
    assert capsys.readouterr() == ("", message)
    assert [p.name for p in tmp_path.iterdir()] == (["small.toml"] if given[0] != "--count" else [])
