"""What every dvqp command that serves a page (the console, the 3-D view) must do."""

from __future__ import annotations

import contextlib
import signal
import socket
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest


def assert_a_taken_port_is_refused(
    start: Callable[[int], int], capsys: pytest.CaptureFixture[str]
) -> None:
    """``start(port)`` on a loopback port something already listens on: exit 2 and one line
    naming the address."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert start(port) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"dvqp: cannot listen on 127.0.0.1:{port}: ") and err.count("\n") == 1


@contextlib.contextmanager
def serving(argv: list[str], cwd: Path) -> Iterator[subprocess.Popen[str]]:
    """The command ``argv`` running (stdout and stderr piped, text), killed if still alive at
    the end."""
    proc = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd
    )
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def interrupted(proc: subprocess.Popen[str]) -> tuple[str, str]:
    """Ctrl-C to a serving command; its remaining stdout and stderr once it ended."""
    proc.send_signal(signal.SIGINT)
    return proc.communicate(timeout=15)
