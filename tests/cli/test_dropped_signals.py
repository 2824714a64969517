"""A Ctrl-C or SIGTERM that lands where CPython drops the exception (a finaliser) still stops
the command at its next step."""

from __future__ import annotations

import io
import signal
import sys

import pytest

from dvqp.cli.progress import ProgressBar, Terminated, interruptible


class Finaliser:
    """Runs Python code when collected: an exception raised in it is printed and dropped."""

    def __del__(self) -> None:
        signal.raise_signal(signal.SIGTERM)  # the handler raises here, inside the finaliser


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # the dropped one
def test_a_sigterm_dropped_in_a_finaliser_stops_the_next_step() -> None:
    bar = ProgressBar(io.StringIO())
    reached = []
    with pytest.raises(Terminated), interruptible():
        Finaliser()  # collected at once: its Terminated is dropped by CPython
        reached.append("the step after the signal ran")
        bar.show(1, 10)  # the command's next step
        reached.append("and the one after it")
    assert reached == ["the step after the signal ran"]  # dropped, then raised at the step


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_a_signal_of_an_earlier_command_does_not_stop_the_next() -> None:
    bar = ProgressBar(io.StringIO())
    with pytest.raises(Terminated), interruptible():
        Finaliser()
        bar.show(1, 10)
    with interruptible():  # the next command in the same process (the console, a test)
        bar.show(2, 10)
        bar.show(10, 10)


def swallowing_library() -> None:
    """A library call that the signal interrupts and that turns it into an error of its own
    (as llvmlite does when a Ctrl-C lands while numba compiles)."""
    try:
        signal.raise_signal(signal.SIGINT)
    except KeyboardInterrupt as exc:
        raise AttributeError("'ValueRef' object has no attribute '_as_parameter_'") from exc


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
def test_a_signal_a_library_turns_into_its_own_error_still_stops_as_the_signal() -> None:
    with pytest.raises(KeyboardInterrupt) as info, interruptible():
        swallowing_library()
    assert not isinstance(info.value, Terminated)
    assert isinstance(info.value.__cause__, AttributeError)


def test_an_error_without_a_signal_stays_that_error() -> None:
    with pytest.raises(AttributeError), interruptible():
        raise AttributeError("no signal")
