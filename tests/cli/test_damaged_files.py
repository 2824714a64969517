"""A damaged or hostile file given to a command (a trajectory to ``plot`` or ``view``, a scene,
a URDF) is one line on stderr and exit 2, never a traceback; an ``.npz`` costs no more memory
than its arrays declare, and an array whose declared size is absurd for what it should hold is
refused before any of it is inflated."""

from __future__ import annotations

import tracemalloc
import zipfile
from pathlib import Path

import numpy as np
import pytest

from dvqp import InputFileError, Trajectory
from dvqp.cli import main
from tests.cli.test_cli import write_scene

DRAWINGS = {  # how each command that reads a trajectory is asked to (its output in tmp)
    "plot": ["-o", "{tmp}/f.png"],
    "plot --gif": ["--gif", "-o", "{tmp}/f.gif"],
    "plot --limits": ["--limits", "-o", "{tmp}/f.png"],
    "plot --3d": ["--3d", "-o", "{tmp}/f.png"],
}


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small run saved by ``dvqp plan``."""
    folder = tmp_path_factory.mktemp("run")
    out = folder / "run.npz"
    assert main(["plan", write_scene(folder), "--backend", "pinv", "-o", str(out)]) == 0
    return out


def one_line_refusal(capsys: pytest.CaptureFixture[str], code: int) -> str:
    """Check the command exited 2 with one line on stderr and nothing on stdout; the line."""
    captured = capsys.readouterr()
    assert code == 2 and captured.out == "", captured
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err, captured.err
    return captured.err.rstrip("\n")


def npy_header(shape: tuple[int, ...], dtype: str = "<f8") -> bytes:
    """An ``.npy`` header (format 1.0) declaring ``shape`` of ``dtype``."""
    text = f"{{'descr': '{dtype}', 'fortran_order': False, 'shape': {shape}, }}"
    pad = 64 - (10 + len(text) + 1) % 64
    text += " " * pad + "\n"
    return b"\x93NUMPY\x01\x00" + len(text).to_bytes(2, "little") + text.encode("latin1")


def bomb(path: Path, arrays: dict[str, np.ndarray], zeros: dict[str, tuple[int, ...]]) -> int:
    """An ``.npz`` of ``arrays`` and of members of zeros of the ``zeros`` shapes, written in
    chunks (never held in memory), deflated: a few hundred kB on disk. Returns the bytes the
    zeros inflate to."""
    total = 0
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for name, value in arrays.items():
            with z.open(f"{name}.npy", "w") as fh:
                np.lib.format.write_array(fh, np.asarray(value))
        chunk = bytes(1 << 22)
        for name, shape in zeros.items():
            size = 8 * int(np.prod(shape))
            total += size
            with z.open(f"{name}.npy", "w", force_zip64=True) as fh:
                fh.write(npy_header(shape))
                for start in range(0, size, len(chunk)):
                    fh.write(chunk[: min(len(chunk), size - start)])
    return total


@pytest.mark.parametrize("command", DRAWINGS)
@pytest.mark.parametrize("cut", [0.25, 0.6, 0.95])
def test_a_truncated_trajectory_is_one_line_for_every_drawing(
    saved: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str, cut: float
) -> None:
    data = saved.read_bytes()
    cut_short = tmp_path / "cut.npz"
    cut_short.write_bytes(data[: int(cut * len(data))])
    args = [a.format(tmp=tmp_path) for a in DRAWINGS[command]]
    line = one_line_refusal(capsys, main(["plot", str(cut_short), *args]))
    assert line.startswith(f"dvqp: {cut_short}: not a dvqp trajectory (damaged"), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cut.npz"]


def test_a_member_whose_bytes_were_garbled_is_one_line(
    saved: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = bytearray(saved.read_bytes())
    for at in range(len(data) // 3, len(data) // 3 + 64):  # inside some member's deflated data
        data[at] ^= 0x5A
    garbled = tmp_path / "garbled.npz"
    garbled.write_bytes(bytes(data))
    line = one_line_refusal(capsys, main(["plot", str(garbled), "-o", str(tmp_path / "f.png")]))
    assert (
        line.startswith(f"dvqp: {garbled}: not a dvqp trajectory (member '") and "damaged" in line
    )


def test_the_view_refuses_a_truncated_trajectory_in_one_line(
    saved: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("viser", reason="the view extra is not installed")
    cut_short = tmp_path / "cut.npz"
    cut_short.write_bytes(saved.read_bytes()[:2000])
    line = one_line_refusal(capsys, main(["view", str(cut_short), "--port", "0"]))
    assert line.startswith(f"dvqp: {cut_short}: not a dvqp trajectory (damaged")


def test_an_array_larger_than_its_samples_is_refused_before_it_is_inflated(
    saved: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with np.load(saved) as data:
        arrays = {name: data[name] for name in data.files if name != "q"}
    hostile = tmp_path / "hostile.npz"
    inflated = bomb(hostile, arrays, {"q": (4_000_000, 13)})  # 416 MB of zeros
    assert hostile.stat().st_size < inflated / 200
    tracemalloc.start()
    try:
        code = main(["plot", str(hostile), "-o", str(tmp_path / "f.png")])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    line = one_line_refusal(capsys, code)
    assert (
        line == f"dvqp: {hostile}: not a dvqp trajectory (member 'q': 4000000 rows for 22 samples)"
    )
    assert peak < 20e6  # bytes: the arrays it declares were never allocated


def test_a_file_declaring_more_than_the_memory_is_refused_before_it_is_inflated(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("dvqp._inputs.physical_memory", lambda: 100_000_000)
    rows = 2_000_000  # each array consistent with the others, together 0.2 GB
    hostile = tmp_path / "big.npz"
    bomb(hostile, {}, {"t": (rows,), "w": (rows,), "tool": (rows, 4), "min_clearance": (rows,)})
    with pytest.raises(InputFileError) as info:
        Trajectory.load(hostile)
    assert str(info.value) == (
        f"{hostile}: not a dvqp trajectory (its arrays declare 112 MB, more than this "
        "machine's 100 MB allow)"
    )


@pytest.mark.parametrize(
    ("member", "reason"),
    [
        (np.array([{"a": 1}], dtype=object), "member 't': pickled Python objects are not read"),
        (np.zeros((3, 3)), "member 't': shape (3, 3), not (samples,)"),
    ],
    ids=["pickled", "not a time axis"],
)
def test_a_hostile_time_axis_is_refused(tmp_path: Path, member: np.ndarray, reason: str) -> None:
    bad = tmp_path / "bad.npz"
    np.savez(bad, t=member)
    with pytest.raises(InputFileError, match=r"not a dvqp trajectory \(") as info:
        Trajectory.load(bad)
    assert str(info.value) == f"{bad}: not a dvqp trajectory ({reason})"


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"\x00" * ((1 << 24) + 1), "larger than 16 MiB: not a scene file"),
        (b"name = '\xff\xfe'\n", "cannot read: 'utf-8' codec can't decode byte 0xff in position 8"),
    ],
    ids=["larger than a scene", "not UTF-8"],
)
def test_a_damaged_or_huge_scene_file_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: bytes, reason: str
) -> None:
    scene = tmp_path / "scene.toml"
    scene.write_bytes(content)
    line = one_line_refusal(capsys, main(["plan", str(scene)]))
    assert line.startswith(f"dvqp: {scene}: {reason}"), line


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_an_endless_scene_file_is_read_no_further_than_the_bound(
    capsys: pytest.CaptureFixture[str],
) -> None:
    line = one_line_refusal(capsys, main(["plan", "/dev/zero"]))
    assert line == "dvqp: /dev/zero: larger than 16 MiB: not a scene file"
