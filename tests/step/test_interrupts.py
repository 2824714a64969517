"""Ctrl-C is never lost: not in the call into compiled code, not inside a solver.

Two places swallowed a SIGINT: numba reads a struct's type with ``PyObject_HasAttr`` on every
call (which clears any exception, a KeyboardInterrupt raised in a property included), and OSQP
catches SIGINT itself during a solve and answers ``interrupted``.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from dvqp.workspace import as_struct

ROOT = Path(__file__).resolve().parents[2]


@dataclasses.dataclass(frozen=True)
class Packed:
    a: np.ndarray


@njit
def first(s):  # type: ignore[no-untyped-def]
    return s.a[0]


@njit
def handed_back(s):  # type: ignore[no-untyped-def]
    return s


def test_a_call_into_compiled_code_runs_no_python_code_where_an_interrupt_is_cleared() -> None:
    packed = as_struct(Packed(np.arange(3.0)))
    first(packed)
    called: list[str] = []

    def profile(frame, event, arg):  # type: ignore[no-untyped-def]
        if event == "call":
            called.append(frame.f_code.co_name)

    sys.setprofile(profile)
    try:
        first(packed)
    finally:
        sys.setprofile(None)
    assert called == ["first"]  # the dispatcher's typing of the struct ran no Python function


class _InterruptedLookup(dict):  # type: ignore[type-arg]
    """numba's unpickling memo, raising KeyboardInterrupt at its ``at``-th lookup (as a
    Ctrl-C handled inside ``numba_unpickle`` does)."""

    def __init__(self, memo: dict, at: int) -> None:  # type: ignore[type-arg]
        super().__init__(memo)
        self.left = at

    def __getitem__(self, key):  # type: ignore[no-untyped-def]
        self.left -= 1
        if self.left == 0:
            raise KeyboardInterrupt
        return super().__getitem__(key)


@pytest.mark.parametrize("at", [1, 2])
def test_an_interrupt_while_a_struct_is_handed_back_stays_an_interrupt(
    at: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    from numba.core import serialize

    packed = as_struct(Packed(np.arange(3.0)))
    handed_back(packed)  # compiled and its constants unpickled once already
    monkeypatch.setattr(
        serialize, "_unpickled_memo", _InterruptedLookup(serialize._unpickled_memo, at)
    )
    with pytest.raises(KeyboardInterrupt):
        handed_back(packed)
    monkeypatch.undo()
    assert first(handed_back(packed)) == 0.0  # and boxing works after


def run_interrupted(body: str, timeout: float = 120.0) -> subprocess.CompletedProcess[str]:
    """Run ``body`` with a handler counting SIGINTs and a thread sending one every 23 ms for
    ``SECONDS`` (then none, so that none lands in the script's own bookkeeping); the script
    ends by printing ``counted <handled> <caught>``."""
    script = (
        textwrap.dedent("""
        import os, signal, threading, time
        handled = caught = 0
        def handler(signum, frame):
            global handled
            handled += 1
            raise KeyboardInterrupt
        def send():  # for SECONDS, then no more: nothing lands in the bookkeeping after
            end = time.monotonic() + SECONDS
            while time.monotonic() < end:
                time.sleep(0.023)
                os.kill(os.getpid(), signal.SIGINT)
        def work():
            pass
        """)
        + textwrap.dedent(body)
        + textwrap.dedent("""
        signal.signal(signal.SIGINT, handler)
        sender = threading.Thread(target=send, daemon=True)
        sender.start()
        while True:
            try:
                while sender.is_alive():
                    try:
                        work()
                    except KeyboardInterrupt:
                        caught += 1
                time.sleep(0.2)  # a signal sent last is handled by now
                break
            except KeyboardInterrupt:  # one that landed between the work calls
                caught += 1
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        print("counted", handled, caught)
        """)
    )
    return subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=timeout, cwd=ROOT
    )


def counts(done: subprocess.CompletedProcess[str]) -> tuple[int, int]:
    """SIGINTs handled and KeyboardInterrupts caught (OSQP prints a line of its own)."""
    last = done.stdout.splitlines()[-1].split()
    assert last[0] == "counted", done.stdout + done.stderr
    return int(last[1]), int(last[2])


def test_no_interrupt_is_lost_while_a_run_steps() -> None:
    done = run_interrupted("""
        from dvqp import load_scene, plan
        scene = load_scene("scenes/long-weld.toml")
        plan(scene, "pinv")
        SECONDS = 4.0
        def work():
            plan(scene, "pinv")
        """)
    handled, caught = counts(done)
    assert done.returncode == 0 and handled > 50 and caught == handled


@pytest.mark.parametrize("backend", ["osqp", "qpsolvers:osqp"])
def test_a_solver_that_catches_the_interrupt_gives_it_back(backend: str) -> None:
    pytest.importorskip("osqp")
    done = run_interrupted(f"""
        import numpy as np
        import solvers
        rng = np.random.default_rng(0)
        M = rng.standard_normal((150, 150))
        problem = solvers.Problem(M @ M.T + np.eye(150), rng.standard_normal(150),
                                  G=rng.standard_normal((300, 150)), h=rng.standard_normal(300))
        backend = solvers.make_backend({backend!r})
        SECONDS = 1.5
        def work():
            backend.reset()
            backend.solve(problem)
        """)
    handled, caught = counts(done)
    assert done.returncode == 0 and handled > 10 and caught == handled


def test_a_ctrl_c_while_a_pool_forks_is_held_back_then_raised() -> None:
    import signal

    from dvqp.bench.execution import sigint_deferred

    before = signal.getsignal(signal.SIGINT)  # a test worker may ignore SIGINT
    reached = []
    with pytest.raises(KeyboardInterrupt), sigint_deferred():
        signal.raise_signal(signal.SIGINT)  # as if it landed in os.fork's hooks
        reached.append("the rest of the block ran")
    assert reached == ["the rest of the block ran"]
    assert signal.getsignal(signal.SIGINT) is before  # restored


def test_outside_the_main_thread_nothing_is_held_back() -> None:
    """Only the main thread may set a signal handler (and alone receives Ctrl-C): a bench
    run from another thread (a library caller's) defers nothing and raises nothing."""
    import signal
    import threading

    from dvqp.bench.execution import sigint_deferred

    before = signal.getsignal(signal.SIGINT)
    outcome: list[object] = []

    def run() -> None:
        try:
            with sigint_deferred():
                outcome.append("ran")
        except BaseException as exc:  # reported to the test's thread
            outcome.append(exc)

    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    assert outcome == ["ran"]
    assert signal.getsignal(signal.SIGINT) is before


@pytest.mark.skipif(not hasattr(os, "fork"), reason="forks")
def test_a_process_forked_while_ctrl_c_is_held_back_ends_on_it_at_once() -> None:
    """A worker forked inside the block (a pool's, a LocalCluster's) inherits the handler:
    Ctrl-C ends it at once with exit code 130, not held back for a raise that never comes."""
    import signal

    from dvqp.bench.execution import sigint_deferred

    with pytest.raises(KeyboardInterrupt), sigint_deferred():
        pid = os.fork()
        if pid == 0:  # the child: Ctrl-C must end it; if it is held, it exits 0 after 5 s
            signal.raise_signal(signal.SIGINT)
            time.sleep(5)
            os._exit(0)
        _, status = os.waitpid(pid, 0)
        signal.raise_signal(signal.SIGINT)  # the parent's own: held, then raised
    assert os.waitstatus_to_exitcode(status) == 130
