"""The compile cache fails soft: an entry that cannot be loaded is discarded and compiled anew
with one note, never a traceback; ``dvqp cache path`` / ``clear`` (solvers/jit.py)."""

from __future__ import annotations

import errno
import hashlib
import importlib
import os
import pickle
import pkgutil
import random
import re
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numba
import pytest
from numba.core.caching import NullCache
from numba.core.dispatcher import Dispatcher

import solvers.jit
from dvqp.cli import main
from dvqp.motion.trajectory import Trajectory
from dvqp.step import stages
from solvers import _fast
from solvers.jit import SoftCache, _EntryFiles, njit
from tests.cli.test_cli import write_scene

ROOT = Path(__file__).resolve().parents[2]
NOTE = re.compile(
    r"dvqp: note: compile cache entry (.+) could not be read \((.+)\): "
    r"discarded, compiled again when needed"
)


def stable(out: str) -> list[str]:
    """A plan's summary less its timings."""
    return [line for line in out.splitlines() if not line.startswith(("step time", "solver"))]


def _twice(x):  # type: ignore[no-untyped-def]
    return 2.0 * x


def run_kernel() -> tuple[int, int]:
    """A fresh dispatcher of ``_twice`` (as in a new process) called once: (hits, misses)."""
    kernel = njit(_twice)
    assert kernel(3.0) == 6.0
    return sum(kernel.stats.cache_hits.values()), sum(kernel.stats.cache_misses.values())


@pytest.fixture
def entry(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """``_twice`` compiled into an empty cache folder: its (index, data) files."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    assert run_kernel() == (0, 1)
    (folder,) = tmp_path.iterdir()
    (index,) = folder.glob("*.nbi")
    (data,) = folder.glob("*.nbc")
    return index, data


def checksummed(payload: bytes) -> bytes:
    return b"dvqp-sha256\n" + hashlib.sha256(payload).digest() + payload


def cut(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def garble(path: Path) -> None:
    raw = bytearray(path.read_bytes())
    raw[len(raw) // 2] ^= 0xFF
    path.write_bytes(bytes(raw))


CORRUPTIONS: dict[str, tuple[int, Callable[[Path], object]]] = {  # (0 index / 1 data, how)
    "index cut short": (0, cut),
    "index empty": (0, lambda p: p.write_bytes(b"")),
    "index garbled": (0, lambda p: p.write_bytes(p.read_bytes()[:40] + b"\x00" * 200)),
    "data cut short": (1, cut),
    "data garbled": (1, garble),
    "data empty": (1, lambda p: p.write_bytes(b"")),
    "data random bytes": (1, lambda p: p.write_bytes(random.Random(0).randbytes(3000))),
    "data a wrong pickle": (1, lambda p: p.write_bytes(checksummed(pickle.dumps((1, 2))))),
    "data missing": (1, lambda p: p.unlink()),
}


@pytest.mark.parametrize("kind", CORRUPTIONS)
def test_an_unreadable_entry_is_recompiled_with_one_note_and_then_loaded(
    entry: tuple[Path, Path], kind: str, capsys: pytest.CaptureFixture[str]
) -> None:
    which, corrupt = CORRUPTIONS[kind]
    corrupt(entry[which])
    capsys.readouterr()
    assert run_kernel() == (0, 1)  # the right value, compiled anew
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 1 and (found := NOTE.fullmatch(lines[0])), lines
    assert found.group(1) == str(entry[which])
    assert run_kernel() == (1, 0)  # the fresh entry loads, silently
    assert capsys.readouterr().err == ""


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their permissions")
def test_an_unreadable_index_is_recompiled_with_one_note(
    entry: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    entry[0].chmod(0)
    capsys.readouterr()
    assert run_kernel() == (0, 1)
    assert "(Permission denied): discarded, compiled again when needed" in capsys.readouterr().err


def test_numba_plain_entries_are_ignored_silently_and_replaced(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    assert numba.njit(cache=True)(_twice)(3.0) == 6.0  # numba's own format, no checksum
    assert run_kernel() == (0, 1)
    assert run_kernel() == (1, 0)
    assert capsys.readouterr().err == ""


def test_a_cache_that_cannot_be_written_leaves_the_run_compiled_with_one_note(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def full(self: object, path: str) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), path)

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(_EntryFiles, "_open_for_write", full)
    monkeypatch.setattr(solvers.jit, "_NOTED", set())
    assert run_kernel() == (0, 1)
    assert run_kernel() == (0, 1)  # nothing was cached
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("dvqp: note: compile cache not written (")
    assert err[0].endswith(": No space left on device): compiled code is not cached")
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]


def test_a_function_with_no_folder_to_cache_in_compiles_uncached_with_one_note(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def nowhere(self: object, py_func: object) -> None:  # numba's words, as it would raise
        raise RuntimeError(f"cannot cache function {py_func!r}: no locator available")

    monkeypatch.setattr(SoftCache, "__init__", nowhere)
    monkeypatch.setattr(solvers.jit, "_NOTED", set())
    kernels = [njit(_twice), njit(_twice)]
    assert [k(3.0) for k in kernels] == [6.0, 6.0]
    assert all(isinstance(k._cache, NullCache) for k in kernels)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("dvqp: note: no compile cache (cannot cache")
    assert err[0].endswith("no locator available): compiled code is not cached")


def test_every_compiled_function_of_dvqp_and_solvers_has_the_soft_cache() -> None:
    jit_module = ROOT / "solvers" / "jit.py"
    numba_jit = re.compile(r"from numba import [^\n]*\bn?jit\b|numba\.n?jit\(")
    sources = [p for pkg in ("dvqp", "solvers") for p in (ROOT / pkg).rglob("*.py")]
    assert not [p for p in sources if p != jit_module and numba_jit.search(p.read_text())]
    dispatchers = []
    for package in ("dvqp", "solvers"):
        pkg = importlib.import_module(package)
        for info in pkgutil.walk_packages(pkg.__path__, f"{package}."):
            module = importlib.import_module(info.name)
            dispatchers += [
                v
                for v in vars(module).values()
                if isinstance(v, Dispatcher) and v.py_func.__module__ == info.name
            ]
    assert len(dispatchers) > 60
    assert all(isinstance(d._cache, SoftCache) for d in dispatchers)


def test_the_command_line_sees_every_module_with_compiled_functions() -> None:
    probe = (
        "import dvqp.cli.main\nfrom solvers.jit import CACHES\n"
        "print('\\n'.join(sorted({c.source for c in CACHES})))"
    )
    run = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, check=True
    )
    kernels = re.compile(r"^@(njit|compiled_on_first_call)\b", re.MULTILINE)
    expected = {
        str(p)
        for pkg in ("dvqp", "solvers")
        for p in (ROOT / pkg).rglob("*.py")
        if kernels.search(p.read_text())
    }
    assert set(run.stdout.split()) == expected


def test_cache_clear_removes_dvqp_entries_only_and_says_how_many(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    caches = [SoftCache(f.py_func) for f in (stages.evaluate, _fast.refresh)]
    mine = SoftCache(_twice)  # a cached function outside dvqp and solvers
    monkeypatch.setattr(solvers.jit, "CACHES", [*caches, mine])
    step, solver, other = (Path(c.cache_path) for c in (*caches, mine))
    removed = {
        step / "stages.evaluate-44.py311.nbi": 100,
        step / "stages.evaluate-44.py311.1.nbc": 1000,
        step / "stages.old-9.py311.2.nbc": 10,  # an older line's orphan
        step / "stages.evaluate-44.py311.nbi.tmp.0a1b": 5,  # a write cut short
        solver / "_fast.x-1.py311.nbi": 7,
    }
    kept = [
        step / "engine.run-3.py311.nbi",
        step / "stages.cpython-311.pyc",
        step / "notes.txt",
        solver / "registry.nbc",
        other / "test_compile_cache._twice-1.py311.nbi",
    ]
    for path, size in [*removed.items(), *((p, 3) for p in kept)]:
        path.write_bytes(b"x" * size)
    assert main(["cache", "path"]) == 0
    assert capsys.readouterr().out.split() == sorted(map(str, (step, solver)))
    assert main(["cache", "clear"]) == 0
    assert capsys.readouterr().out == "removed 5 compile cache files (1,122 bytes)\n"
    assert sorted(p for p in tmp_path.rglob("*") if p.is_file()) == sorted(kept)
    assert main(["cache", "clear"]) == 0
    assert capsys.readouterr().out == "removed 0 compile cache files (0 bytes)\n"


@pytest.fixture(scope="module")
def filled(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, str], list[str], str]:
    """An empty NUMBA_CACHE_DIR filled by ``dvqp plan`` (compiles for ~25 s of CPU), then by
    the next run, which compiles the step loop alone (dvqp.motion.follow.COMPILE): the
    environment, the command and its output."""
    folder = tmp_path_factory.mktemp("compile-cache")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(folder / "cache"))
    saved = folder / "run.npz"
    argv = [sys.executable, "-m", "dvqp", "plan", write_scene(folder), "--backend", "pinv"]
    argv += ["-o", str(saved)]
    done = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert done.returncode == 0, done.stderr
    assert "compiling the step's kernels" in done.stderr
    # compiled before the first step, none in a step's time (a compile takes 0.1 s or more)
    assert Trajectory.load(saved).step_time.max() < 0.05
    loop = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert loop.returncode == 0 and stable(loop.stdout) == stable(done.stdout)
    said = loop.stderr.splitlines()
    assert len(said) == 2 and said[0].startswith("dvqp: compiling the run's step loop"), said
    return env, argv, done.stdout


def test_a_plan_over_a_damaged_cache_exits_0_with_a_note_and_the_next_runs_clean(
    filled: tuple[dict[str, str], list[str], str],
) -> None:
    env, argv, expected = filled
    cache = Path(env["NUMBA_CACHE_DIR"])
    damaged = [
        next(cache.glob("kinematics_*/model.kinematics-*.nbi")),
        *(
            next(cache.glob(f"{module}_*/{kernel}-*.1.nbc"))
            for module, kernel in [
                ("geometry", "measure.measure_chain"),
                ("geometry", "real_links.real_links"),
                ("step", "stages.evaluate"),
            ]
        ),
    ]
    cut(damaged[0])
    garble(damaged[1])
    damaged[2].write_bytes(b"")
    damaged[3].write_bytes(random.Random(1).randbytes(4000))
    run = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert (
        run.returncode == 0
        and stable(run.stdout) == stable(expected)
        and "Traceback" not in run.stderr
    )
    said = run.stderr.splitlines()  # the recompiling is announced (dvqp/cli/compiling.py)
    compiling = [line for line in said if line.startswith(("dvqp: compiling ", "dvqp: compiled "))]
    assert len(compiling) in (0, 2)
    notes = [NOTE.fullmatch(line) for line in said if line not in compiling]
    assert all(notes) and sorted(n.group(1) for n in notes if n) == sorted(map(str, damaged))
    again = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=ROOT, check=False)
    assert again.returncode == 0 and stable(again.stdout) == stable(expected) and again.stderr == ""
    files = [p for p in cache.rglob("*") if p.is_file()]
    clear = [sys.executable, "-m", "dvqp", "cache", "clear"]
    done = subprocess.run(clear, capture_output=True, text=True, env=env, cwd=ROOT, check=True)
    assert done.stdout.startswith(f"removed {len(files)} compile cache files (")
    assert not [p for p in cache.rglob("*") if p.is_file()]


def _shifted_double(offset: float) -> Callable[[float], float]:
    def kernel(x: float) -> float:
        return 2.0 * x + offset  # a constant of the compiled code

    return kernel


def _first_calls(kernel: Dispatcher, threads: int) -> list[object]:
    """What ``kernel(1.0)`` gave in each of ``threads`` threads released at once."""
    import threading

    barrier, answers = threading.Barrier(threads), []

    def first_call() -> None:
        barrier.wait()
        try:
            answers.append(kernel(1.0))
        except RuntimeError as exc:  # numba's 'compilation disabled' (before the lock)
            answers.append(exc)

    started = [threading.Thread(target=first_call) for _ in range(threads)]
    for thread in started:
        thread.start()
    for thread in started:
        thread.join()
    return answers


def test_first_calls_from_many_threads_at_once_all_get_the_answer() -> None:
    from numba import types

    from solvers.jit import compiled_on_first_call

    for offset in (0.0, 1.0, 2.0):  # a fresh dispatcher each round: a first call each time
        kernel = compiled_on_first_call(types.float64(types.float64))(_shifted_double(offset))
        assert _first_calls(kernel, 6) == [2.0 + offset] * 6
        assert len(kernel.overloads) == 1


def test_ready_loads_a_cached_kernel_and_never_compiles_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``solvers.jit.ready``: a kernel neither compiled nor cached is not ready (and is not
    compiled); one compiled in the process is; a fresh dispatcher (as in a new process)
    loads the cached one and counts no compile (``compiled_count``)."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    fresh = njit(_twice)
    before = solvers.jit.compiled_count()
    assert not solvers.jit.ready(fresh, (3.0,))
    assert not fresh.overloads and solvers.jit.compiled_count() == before
    assert fresh(3.0) == 6.0
    assert solvers.jit.compiled_count() == before + 1
    assert solvers.jit.ready(fresh, (3.0,))
    again = njit(_twice)
    assert solvers.jit.ready(again, (3.0,))
    assert sum(again.stats.cache_hits.values()) == 1 and len(again.overloads) == 1
    assert again(3.0) == 6.0
    assert not solvers.jit.ready(again, (3,))  # int64: another overload, not cached
    assert solvers.jit.compiled_count() == before + 1
