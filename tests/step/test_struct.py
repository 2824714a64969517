"""The packed struct: a dataclass of arrays crosses into compiled code as one value."""

from __future__ import annotations

import dataclasses
import gc
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
from numba import njit

from dvqp.workspace import as_struct


@dataclasses.dataclass(frozen=True)
class Inner:
    a: np.ndarray
    k: float


@dataclasses.dataclass(frozen=True)
class Outer:
    x: np.ndarray
    inner: Inner
    n: int


@njit
def _bump_and_sum(s):  # type: ignore[no-untyped-def]
    s.inner.a[0] += 1.0
    return s.x.sum() + s.inner.a.sum() + s.inner.k + s.n


def test_nested_dataclasses_share_their_arrays_and_outlive_the_dataclass() -> None:
    a = np.ones(3)
    packed = as_struct(Outer(np.arange(4.0), Inner(a, 2.5), 7))
    assert _bump_and_sum(packed) == 6.0 + 4.0 + 2.5 + 7  # written before the read
    assert a[0] == 2.0  # the very array, not a copy
    del a
    gc.collect()
    assert _bump_and_sum(packed) == 6.0 + 5.0 + 2.5 + 7  # the struct holds its own reference


@pytest.mark.parametrize(
    ("field", "message"),
    [
        (np.ones((3, 2))[:, 0], "C-contiguous"),
        ("text", "cannot pack a str"),
    ],
)
def test_fields_of_another_kind_are_refused_by_name(field: object, message: str) -> None:
    with pytest.raises(TypeError, match=f"x: .*{message}"):
        as_struct(Outer(field, Inner(np.ones(1), 0.0), 0))  # type: ignore[arg-type]


def test_read_only_arrays_are_refused() -> None:
    frozen = np.ones(3)
    frozen.flags.writeable = False
    with pytest.raises(TypeError, match="x: a packed array must be C-contiguous, writable"):
        as_struct(Outer(frozen, Inner(np.ones(1), 0.0), 0))


def test_every_struct_and_array_is_freed_with_its_owner() -> None:
    probe = (
        "import gc, numpy as np\n"
        "from numba.core.runtime import rtsys\n"
        "from tests.step.test_struct import Inner, Outer\n"
        "from dvqp.workspace import as_struct\n"
        "as_struct(Outer(np.ones(2), Inner(np.ones(3), 1.0), 1)); gc.collect()\n"
        "s0 = rtsys.get_allocation_stats()\n"
        "for _ in range(100): as_struct(Outer(np.ones(2), Inner(np.ones(3), 1.0), 1))\n"
        "gc.collect(); s1 = rtsys.get_allocation_stats()\n"
        "print(s1.mi_alloc - s0.mi_alloc, s1.mi_free - s0.mi_free)\n"
    )
    made, freed = map(int, _run_probe(probe).split())
    assert made == freed == 100 * 4  # two arrays and two structs a round


@dataclasses.dataclass(frozen=True)
class Mixed:
    flag: bool
    x: np.ndarray
    small: np.int32
    on: np.bool_
    m: np.ndarray
    scale: np.float32
    idx: np.ndarray
    inner: Inner
    last: bool


@njit
def _fields(s):  # type: ignore[no-untyped-def]
    return (
        s.flag,
        s.x.sum(),
        s.small,
        s.on,
        s.m[1, 0],
        s.scale,
        s.idx[2],
        s.inner.a.sum(),
        s.inner.k,
        s.last,
    )


def test_every_kind_of_field_reads_back_as_written_whatever_its_alignment() -> None:
    m = np.arange(6.0).reshape(3, 2)
    inner = Inner(np.ones(4), -1.25)
    numbers = np.int32(-7), np.bool_(False)
    value = Mixed(
        True, np.arange(5.0), *numbers, m, np.float32(0.5), np.array([4, 5, 6]), inner, True
    )
    assert _fields(as_struct(value)) == (True, 10.0, -7, False, 2.0, 0.5, 6, 4.0, -1.25, True)


@njit
def _view(s):  # type: ignore[no-untyped-def]
    return s.x[1:3]


@njit
def _rebind(s, a):  # type: ignore[no-untyped-def]
    s.x = a
    return s.x.sum()


def test_a_view_outlives_its_struct_and_dataclass() -> None:
    packed = as_struct(Outer(np.arange(4.0) + 10.0, Inner(np.ones(1), 0.0), 0))
    view = _view(packed)
    del packed
    gc.collect()
    np.testing.assert_array_equal(view, [11.0, 12.0])  # the view holds the array's memory


def test_a_field_a_compiled_function_rebinds_is_freed_once_with_the_struct() -> None:
    probe = (
        "import gc, numpy as np\n"
        "from numba.core.runtime import rtsys\n"
        "from tests.step.test_struct import Inner, Outer, _rebind\n"
        "from dvqp.workspace import as_struct\n"
        "s = as_struct(Outer(np.ones(2), Inner(np.ones(3), 1.0), 1))\n"
        "_rebind(s, np.ones(5)); del s; gc.collect()\n"
        "s0 = rtsys.get_allocation_stats()\n"
        "for _ in range(50):\n"
        "    s = as_struct(Outer(np.ones(2), Inner(np.ones(3), 1.0), 1))\n"
        "    assert _rebind(s, np.ones(5)) == 5.0\n"
        "    del s\n"
        "gc.collect(); s1 = rtsys.get_allocation_stats()\n"
        "print(s1.mi_alloc - s0.mi_alloc, s1.mi_free - s0.mi_free)\n"
    )
    made, freed = map(int, _run_probe(probe).split())
    assert made == freed == 50 * 5  # two structs, two arrays, and the array rebound


def _run_probe(probe: str) -> str:
    """What ``probe`` prints, run in a fresh interpreter counting the runtime's allocations."""
    env = dict(os.environ, NUMBA_NRT_STATS="1")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    run = subprocess.run(
        [sys.executable, "-c", probe],
        capture_output=True,
        text=True,
        env=env,
        cwd=root,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    return run.stdout


@dataclasses.dataclass(frozen=True)
class Four:
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray


def test_building_structs_while_other_threads_count_references_keeps_the_count() -> None:
    shared = np.zeros(3)
    value = Four(shared, shared, shared, shared)
    as_struct(value)
    gc.collect()
    before = sys.getrefcount(shared)
    stop = threading.Event()

    def churn() -> None:  # increfs and decrefs the array, the GIL held
        slots: list[object] = [None] * 64
        while not stop.is_set():
            for i in range(64):
                slots[i] = shared
            for i in range(64):
                slots[i] = None

    threads = [threading.Thread(target=churn) for _ in range(3)]
    for thread in threads:
        thread.start()
    try:
        for _ in range(2000):  # the runtime's helper increfs the array: safe with the GIL only
            packed = as_struct(value)
            del packed
    finally:
        stop.set()
        for thread in threads:
            thread.join()
    gc.collect()
    assert sys.getrefcount(shared) == before


def test_an_item_not_of_its_fields_type_is_refused_before_it_is_written() -> None:
    from dvqp.workspace import struct_memory

    kind = as_struct(Outer(np.zeros(3), Inner(np.ones(1), 0.0), 1))._numba_type_
    inner = as_struct(Inner(np.ones(1), 0.0))
    with pytest.raises(TypeError, match="not a 1-d float64 ndarray"):
        struct_memory.build(kind, [np.zeros((2, 3, 4)), inner, 1])  # would overrun the field
    with pytest.raises(TypeError, match="not a struct of type"):
        struct_memory.build(
            kind, [np.zeros(3), as_struct(Outer(np.zeros(1), Inner(np.ones(1), 0.0), 1)), 1]
        )


@pytest.mark.parametrize(
    "field", [np.float16(1.0), np.array([object()], dtype=object)], ids=["float16", "object"]
)
def test_a_field_numba_cannot_lay_out_is_a_type_error(field: object) -> None:
    with pytest.raises(TypeError):
        as_struct(Outer(np.zeros(1), Inner(np.ones(1), 0.0), field))  # type: ignore[arg-type]
