"""Fused kernels run as the plain loop does, stop at a checked status, and fall back safely."""

from __future__ import annotations

import importlib
import signal
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit

from dvqp.compiled import Kernel
from dvqp.compiled.fusion import fuse
from dvqp.compiled.interrupts import _CompilerLockListener


@njit(cache=True)
def add_scaled(source, factor, out):  # type: ignore[no-untyped-def]
    for i in range(out.shape[0]):
        out[i] += factor * source[i]


@njit(cache=True)
def status_if_negative(values, limit):  # type: ignore[no-untyped-def]
    for i in range(values.shape[0]):
        if values[i] < limit:
            return i
    return -1


@njit(cache=True)
def fill_matrix(rows, value, flags, out):  # type: ignore[no-untyped-def]
    for r in range(out.shape[0]):
        for c in range(out.shape[1]):
            out[r, c] = value * rows[r] if flags[r] else 0.0


def kernels(source: np.ndarray, out: np.ndarray, matrix: np.ndarray) -> list[Kernel]:
    rows = np.arange(3, dtype=np.int64)
    flags = np.array([True, False, True])
    frozen = np.array([1.0, 2.0, 3.0])
    frozen.flags.writeable = False  # a constant of the run: packed as a copy
    return [
        Kernel(add_scaled, (source, 2.0, out)),
        Kernel(add_scaled, (frozen, -1.0, out)),
        Kernel(status_if_negative, (out, -5.0), True),
        Kernel(fill_matrix, (rows, 0.5, flags, matrix)),
    ]


def test_a_fused_call_equals_the_kernels_called_in_turn() -> None:
    source, out, matrix = np.array([1.0, -1.0, 4.0]), np.zeros(3), np.zeros((3, 2))
    run = fuse(kernels(source, out, matrix))
    assert run.fused  # type: ignore[attr-defined]  # a generated driver, not the loop
    assert run() == -1
    np.testing.assert_array_equal(out, 2.0 * source - [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(matrix, [[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    source[:] = [0.0, 1.0, 0.0]  # the arrays are shared, not copied: new data is seen
    run()
    np.testing.assert_array_equal(out, [0.0, -4.0, 2.0])  # accumulated over both calls


def test_a_checked_kernel_stops_the_sequence_with_its_status() -> None:
    source, out, matrix = np.array([-9.0, 0.0, 0.0]), np.zeros(3), np.full((3, 2), 7.0)
    assert fuse(kernels(source, out, matrix))() == 0  # out[0] = -19 < -5
    assert (matrix == 7.0).all()  # the kernel after it did not run


def test_without_a_writable_cache_the_kernels_run_in_a_plain_loop(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    monkeypatch.setenv("DVQP_CACHE_DIR", str(blocker))
    source, out, matrix = np.array([1.0, -1.0, 4.0]), np.zeros(3), np.zeros((3, 2))
    run = fuse(kernels(source, out, matrix)[:2])  # a sequence no other test has fused
    assert not run.fused  # type: ignore[attr-defined]
    assert run() == -1
    np.testing.assert_array_equal(out, 2.0 * source - [1.0, 2.0, 3.0])


def test_a_kernel_that_is_not_a_module_level_numba_function_runs_unfused() -> None:
    calls: list[int] = []

    def python_kernel(out: np.ndarray) -> None:
        calls.append(1)
        out[0] = 42.0

    out = np.zeros(3)
    run = fuse([Kernel(add_scaled, (np.ones(3), 1.0, out)), Kernel(python_kernel, (out,))])
    assert not run.fused  # type: ignore[attr-defined]
    assert run() == -1 and calls == [1] and out[0] == 42.0


def test_an_interrupt_while_numba_holds_its_compiler_lock_is_raised_after_it() -> None:
    listener, done = _CompilerLockListener(), []
    with pytest.raises(KeyboardInterrupt):
        listener.on_start(None)  # type: ignore[arg-type]  # numba takes its compiler lock
        signal.raise_signal(signal.SIGINT)
        done.append("the compilation ran to its end")
        listener.on_end(None)  # type: ignore[arg-type]  # and releases it
    assert done == ["the compilation ran to its end"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


KERNEL_SOURCE = """
from numba import njit


@njit(cache=True)
def scaled(out):
    out[0] = {factor} * 2.0
"""


def test_a_changed_kernel_gets_a_new_driver_not_the_cached_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("DVQP_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.syspath_prepend(str(tmp_path))
    module = tmp_path / "user_kernels_for_fusion.py"
    results = []
    for factor in (3.0, 7.5):
        module.write_text(KERNEL_SOURCE.format(factor=factor), encoding="utf-8")
        sys.modules.pop("user_kernels_for_fusion", None)
        user = importlib.import_module("user_kernels_for_fusion")
        out = np.zeros(1)
        fuse([Kernel(user.scaled, (out,))])()
        results.append(out[0])
    assert results == [6.0, 15.0]
    assert len(list((tmp_path / "cache" / "fused").glob("driver_*.py"))) == 2


def test_a_cache_folder_others_may_write_is_not_used(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shared = tmp_path / "shared"
    shared.mkdir(mode=0o777)
    shared.chmod(0o777)
    monkeypatch.setenv("DVQP_CACHE_DIR", str(shared))
    out = np.zeros(3)
    fuse([Kernel(add_scaled, (np.ones(3), 1.0, out))])()
    np.testing.assert_array_equal(out, np.ones(3))  # computed, by the plain loop
    assert not (shared / "fused").exists()
