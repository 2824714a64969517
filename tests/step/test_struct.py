"""The packed struct: a dataclass of arrays crosses into compiled code as one value."""

from __future__ import annotations

import dataclasses
import gc
import os
import subprocess
import sys

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
    made, freed = map(int, run.stdout.split())
    assert made == freed == 100 * 4  # two arrays and two structs a round
