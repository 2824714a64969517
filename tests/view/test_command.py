"""``dvqp view``: its one-line errors (exit 2), the view's server in process (its page, the arm
at the slider's sample), and the real command printing one URL line, serving viser's own
client, and ending on Ctrl-C."""

from __future__ import annotations

import argparse
import re
import signal
import sys
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from dvqp.cli import view as view_cli
from dvqp.cli.main import _run, main
from dvqp.view import server
from tests import runs
from tests.servers import assert_a_taken_port_is_refused, interrupted, serving

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "scenes" / "paper-two-inlets.toml"
URL = re.compile(r"^http://127\.0\.0\.1:(\d+)/$")


def parse(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="dvqp")
    view_cli.register(parser.add_subparsers())
    return parser.parse_args(["view", *argv])


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("view")
    runs.run("paper-two-inlets", "daqp").save(folder / "paper.npz")
    np.savez(folder / "other.npz", x=np.zeros(3))
    (folder / "notes.txt").write_text("not a trajectory\n")
    (folder / "bad.toml").write_text("[pipe]\nradius = -1\n")
    return folder


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("missing.npz", "{f}: cannot read: No such file or directory"),
        ("other.npz", "{f}: not a dvqp trajectory (not written by 'dvqp plan')"),
        ("notes.txt", "{f}: not a dvqp trajectory (not an .npz file)"),
        ("bad.toml", "{f}: pipe.radius: must be >= 0.001 m, got -1.0"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(saved: Path, capsys, name, message) -> None:  # type: ignore[no-untyped-def]
    path = saved / name
    code = main(["view", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and err == f"dvqp: {message.format(f=path)}\n"


def test_a_scene_file_takes_no_scene_option(capsys) -> None:  # type: ignore[no-untyped-def]
    assert _run(parse(str(PAPER), "--scene", str(PAPER))) == 2
    assert capsys.readouterr().err == "dvqp: --scene goes with a trajectory, not a scene file\n"


def test_without_viser_it_says_how_to_install_it(monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(server, "AVAILABLE", False)
    assert _run(parse(str(PAPER))) == 2
    assert capsys.readouterr().err == f"dvqp: {server.MISSING}\n"
    assert server.MISSING == "the view needs viser: pip install 'dvqp[view]'"


def test_a_port_in_use_is_refused(capsys) -> None:  # type: ignore[no-untyped-def]
    pytest.importorskip("viser", reason="the view extra is not installed")
    assert_a_taken_port_is_refused(
        lambda port: _run(parse(str(PAPER), "--port", str(port))), capsys
    )


def test_the_view_serves_its_page_and_puts_the_arm_at_the_sliders_sample(saved: Path) -> None:
    pytest.importorskip("viser", reason="the view extra is not installed")
    view = view_cli.view_of(parse(str(saved / "paper.npz")))
    shown = server.View(view, "127.0.0.1", 0)
    try:
        with urllib.request.urlopen(shown.url, timeout=5) as page:
            assert page.status == 200 and b"<html" in page.read().lower()
        last = len(view.t) - 1
        assert int(shown.sample.value) == last and shown.time.value == f"{view.t[last]:.3f}"
        shown.sample.value = 7
        assert np.allclose(shown.arm.points[:, 0], view.chain[7, :-1], atol=1e-6)
        assert np.allclose(shown.arm.points[-1, 1], view.chain[7, -1], atol=1e-6)
        assert shown.time.value == f"{view.t[7]:.3f}"
        shown.play.value = True  # the player moves the slider on
        deadline = 50
        while int(shown.sample.value) in (7,) and deadline:
            shown._stop.wait(0.05)
            deadline -= 1
        assert int(shown.sample.value) != 7
    finally:
        shown.close()


def test_the_command_prints_one_url_line_serves_it_and_ends_on_ctrl_c(saved: Path) -> None:
    pytest.importorskip("viser", reason="the view extra is not installed")
    with serving([sys.executable, "-m", "dvqp", "view", str(PAPER), "--port", "0"], ROOT) as proc:
        line = proc.stdout.readline().rstrip("\n")  # type: ignore[union-attr]
        assert URL.match(line), line
        with urllib.request.urlopen(line, timeout=5) as page:
            assert page.status == 200
        out, err = interrupted(proc)
    assert proc.returncode == 130 and out == "" and err == "dvqp: interrupted\n"


@pytest.mark.parametrize("host", ["0.0.0.0", "::", "192.168.1.20", "viewer.example"])
def test_an_address_other_than_the_loopback_is_refused_without_insecure(
    host: str, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("viser", reason="the view extra is not installed")
    assert main(["view", str(PAPER), "--host", host, "--port", "0"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == (
        f"dvqp: --host {host}: not a loopback address, and the view has no access token: "
        "anyone who reaches it sees the run (add --insecure to serve it there anyway, on a "
        "network you trust)\n"
    )


def test_with_insecure_it_serves_on_the_network_and_warns_on_stderr() -> None:
    pytest.importorskip("viser", reason="the view extra is not installed")
    argv = [sys.executable, "-m", "dvqp", "view", str(PAPER), "--host", "0.0.0.0", "--port", "0"]
    with serving([*argv, "--insecure"], ROOT) as proc:
        line = proc.stdout.readline().rstrip("\n")  # type: ignore[union-attr]
        found = re.match(r"^http://0\.0\.0\.0:(\d+)/$", line)
        assert found, line
        warning = proc.stderr.readline()  # type: ignore[union-attr]
        assert (
            warning
            == f"dvqp: warning: {line} has no access token: anyone who reaches it sees the run\n"
        )
        with urllib.request.urlopen(f"http://127.0.0.1:{found[1]}/", timeout=5) as page:
            assert page.status == 200
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=15)
    assert proc.returncode == 143 and out == "" and err == "dvqp: terminated\n"
