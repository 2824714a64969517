"""Text that comes from a file is shown safely: control and bidi characters escaped, one line
stays one line; an empty output name is refused."""

from __future__ import annotations

import unicodedata
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dvqp.cli import main
from dvqp.scenes import loads
from tests.cli.test_cli import write_scene

HOSTILE = "x\u001b[31mRED\r\nfake line\u0000\u202eabc\u2066"


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string, every character that needs it as a \\u escape."""
    body = "".join(c if c.isprintable() and c not in '"\\' else f"\\U{ord(c):08x}" for c in text)
    return f'"{body}"'


def unsafe(text: str) -> list[str]:
    """The characters of ``text`` a terminal would act on (other than the line ends)."""
    return [c for c in text if c != "\n" and unicodedata.category(c)[0] in "CZ" and c != " "]


def scene_named(folder: Path, name: str) -> str:
    path = Path(write_scene(folder))
    text = path.read_text(encoding="utf-8").replace('name = "small"', f"name = {toml_string(name)}")
    path.write_text(text, encoding="utf-8")
    return str(path)


def test_a_hostile_scene_name_is_printed_escaped_on_its_own_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", scene_named(tmp_path, HOSTILE), "--backend", "pinv"]) == 0
    out = capsys.readouterr().out
    assert unsafe(out) == []
    scene_line = next(line for line in out.splitlines() if line.startswith("scene "))
    assert "x\\x1b[31mRED\\r\\nfake line\\x00\\u202eabc\\u2066 (" in scene_line
    assert not any(line.startswith("fake line") for line in out.splitlines())


def test_an_error_quoting_hostile_text_is_one_escaped_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = Path(write_scene(tmp_path))
    text = path.read_text(encoding="utf-8")
    path.write_text(text.replace('model = "ndt13"', f"model = {toml_string(HOSTILE)}"), "utf-8")
    assert main(["plan", str(path), "--backend", "pinv"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"dvqp: {path}: robot.model") and not unsafe(err)


@settings(max_examples=60, deadline=None)
@given(
    name=st.text(st.characters(exclude_categories=("Cs",)), max_size=30),
    description=st.text(st.characters(exclude_categories=("Cs",)), max_size=30),
)
def test_any_scene_name_or_description_loads_printable(name: str, description: str) -> None:
    text = (Path(__file__).parents[2] / "scenes" / "joint-limit.toml").read_text("utf-8")
    head = f"name = {toml_string(name)}\ndescription = {toml_string(description)}\n"
    body = "\n".join(
        line for line in text.splitlines() if not line.startswith(("name =", "description ="))
    )
    scene = loads(head + body)
    assert scene.name.isprintable() and scene.description.isprintable()
    assert scene.name == name or "\\" in scene.name  # unchanged unless something was escaped


@pytest.mark.parametrize(
    "command",
    [
        ["plan", "{scene}", "-o", ""],
        ["plan", "{scene}", "-o", " "],
        ["compare", "{scene}", "--json", ""],
        ["bench", "--count", "1", "--csv", ""],
    ],
)
def test_an_empty_output_name_is_refused_before_any_run(
    command: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path)
    assert main([a.format(scene=scene) for a in command]) == 2
    captured = capsys.readouterr()
    assert captured.err == "dvqp: output: empty file name\n" and captured.out == ""


def test_an_error_the_console_sends_shows_hostile_text_escaped() -> None:
    import json

    from dvqp.console import protocol

    message = json.loads(protocol.error(f"unknown backend {HOSTILE!s}"))["message"]
    assert message.isprintable() and "\\x1b[31mRED\\r\\n" in message
