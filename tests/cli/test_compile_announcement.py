"""A command that compiles says so on stderr, redirected or not; one that loads says nothing."""

from __future__ import annotations

import io
import time

import numba
import pytest

from dvqp.cli import compiling


def _fresh_kernel():  # type: ignore[no-untyped-def]
    """A numba function nothing has compiled yet (a new closure each call)."""
    offset = time.perf_counter()

    @numba.njit(cache=False)
    def kernel(x):  # type: ignore[no-untyped-def]
        total = 0.0
        for i in range(x.shape[0]):
            total += x[i] * offset
        return total

    return kernel


def test_compiling_is_announced_in_one_line_then_timed(monkeypatch: pytest.MonkeyPatch) -> None:
    import numpy as np

    monkeypatch.setattr(compiling, "AFTER", 0.01)
    out = io.StringIO()  # not a terminal: the line is written all the same
    with compiling.announced("plan", out):
        _fresh_kernel()(np.ones(3))
        time.sleep(0.3)  # the watcher polls every 0.1 s
    lines = out.getvalue().splitlines()
    assert len(lines) == 2, lines
    assert lines[0].startswith("dvqp: compiling the step's kernels: the first run after")
    assert f"about {compiling.ESTIMATES['plan']} s" in lines[0]
    assert lines[1].startswith("dvqp: compiled ") and lines[1].endswith(" s, cached")


def test_a_command_that_compiles_nothing_says_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(compiling, "AFTER", 0.01)
    out = io.StringIO()
    with compiling.announced("plan", out):
        time.sleep(0.3)
    assert out.getvalue() == ""


def test_the_step_loop_compiled_alone_is_announced_as_such(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The run after the first compiles the step loop alone (dvqp.motion.follow.COMPILE):
    its line names the loop and its own estimate, not the first run's."""
    import numpy as np

    monkeypatch.setattr(compiling, "AFTER", 0.01)
    monkeypatch.setattr(compiling, "LOOP_MODULE", __name__)  # this module's kernel as the loop
    out = io.StringIO()
    with compiling.announced("plan", out):
        _fresh_kernel()(np.ones(3))
        time.sleep(0.3)
    lines = out.getvalue().splitlines()
    assert len(lines) == 2, lines
    assert lines[0].startswith("dvqp: compiling the run's step loop: once, the run after the")
    assert f"about {compiling.LOOP} s" in lines[0]
