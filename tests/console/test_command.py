"""``dvqp console``: its arguments, its one-line errors (exit 2), and the real command printing
one URL line with a fresh token, serving it, and ending on Ctrl-C."""

from __future__ import annotations

import argparse
import re
import sys
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from dvqp.cli import console as console_cli
from dvqp.cli.main import _parser, _run
from dvqp.console import server
from tests.servers import assert_a_taken_port_is_refused, interrupted, serving

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenes" / "paper-two-inlets.toml"
URL = re.compile(r"^http://127\.0\.0\.1:(\d+)/\?token=([A-Za-z0-9_-]{43})$")

# ``dvqp console`` as dvqp.cli.main runs it, for as long as main.py does not register it.
SCRIPT = """
import argparse, sys
from dvqp.cli import console
from dvqp.cli.main import _run
from dvqp.cli.progress import interruptible, warnings_summed_up
parser = argparse.ArgumentParser(prog="dvqp")
console.register(parser.add_subparsers())
args = parser.parse_args(sys.argv[1:])
try:
    with interruptible(), warnings_summed_up() as code:
        code.append(_run(args))
    sys.exit(code[0])
except KeyboardInterrupt:
    print("dvqp: interrupted", file=sys.stderr)
    sys.exit(130)
"""


def wired() -> bool:
    """dvqp/cli/main.py registers the console subcommand."""
    actions = [a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction)]
    return any("console" in a.choices for a in actions)


def command(*args: str) -> list[str]:
    if wired():
        return [sys.executable, "-m", "dvqp", "console", *args]
    return [sys.executable, "-c", SCRIPT, "console", *args]


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="dvqp")
    console_cli.register(parser.add_subparsers())
    return parser.parse_args(["console", *argv])


def test_the_arguments_and_their_defaults() -> None:
    args = parse(str(PAPER))
    assert (args.backend, args.host, args.port, args.run) == (
        "daqp",
        "127.0.0.1",
        8765,
        console_cli.run,
    )
    assert parse(str(PAPER), "--port", "0", "--host", "::1").port == 0
    with pytest.raises(SystemExit):
        parse(str(PAPER), "--port", "70000")


@pytest.mark.skipif(not wired(), reason="dvqp/cli/main.py does not register 'console' yet")
def test_main_registers_the_console() -> None:
    from dvqp.cli import main

    assert main(["console", "--help"]) == 0


def test_without_the_extra_it_says_what_to_install(monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(server, "AVAILABLE", False)
    assert _run(parse(str(PAPER))) == 2
    err = capsys.readouterr().err
    assert err == "dvqp: the console needs aiohttp: pip install 'dvqp[console]'\n"


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["nope.toml"], "dvqp: nope.toml: cannot read: No such file or directory\n"),
        ([str(PAPER), "--backend", "nope"], "dvqp: unknown backend 'nope'; installed: pinv"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(argv: list[str], message: str, capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("aiohttp", reason="the console extra is not installed")
    assert _run(parse(*argv)) == 2
    err = capsys.readouterr().err
    assert err.startswith(message) and err.count("\n") == 1


def test_a_port_in_use_is_one_line_and_exit_2(capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("aiohttp", reason="the console extra is not installed")
    assert_a_taken_port_is_refused(
        lambda port: _run(parse(str(PAPER), "--port", str(port))), capsys
    )


def get(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return int(r.status)
    except urllib.error.HTTPError as exc:
        return exc.code


def test_the_command_prints_one_url_line_serves_it_and_ends_on_ctrl_c() -> None:
    pytest.importorskip("aiohttp", reason="the console extra is not installed")
    with serving(command(str(PAPER), "--port", "0"), ROOT) as proc:
        line = proc.stdout.readline().rstrip("\n")  # type: ignore[union-attr]
        found = URL.match(line)
        assert found, line
        port, token = found.groups()
        assert get(f"http://127.0.0.1:{port}/?token={token}") == 200
        assert get(f"http://127.0.0.1:{port}/") == 401
        assert get(f"http://127.0.0.1:{port}/?token={token[:-1]}") == 401
        out, err = interrupted(proc)
    assert proc.returncode == 130 and out == "" and err == "dvqp: interrupted\n"
