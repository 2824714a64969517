"""The memory a long run announces is the memory it takes (within 20 %)."""

from __future__ import annotations

import tracemalloc
from pathlib import Path

import pytest

from dvqp import load_scene
from dvqp.cli import main
from dvqp.cli.progress import RunEstimate
from dvqp.motion import follow

SCENES = Path(__file__).resolve().parents[2] / "scenes"


def held_still(folder: Path, seconds: float) -> str:
    """The paper scene with one JOG of ``seconds`` that holds the tool still."""
    text = (SCENES / "paper-two-inlets.toml").read_text(encoding="utf-8")
    motion = "[motion]\ndt = 0.005\n[[motion.jog]]\n"
    motion += f"duration = {seconds}\nvelocity = [0.0, 0.0, 0.0, 0.0]\n"
    path = folder / f"still-{seconds:g}.toml"
    path.write_text(text[: text.index("[motion]")] + motion, encoding="utf-8")
    return str(path)


def test_the_announced_memory_of_a_run_is_its_traced_peak_within_a_fifth(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(follow, "COMPILE", "always")  # the warm-up compiles the step loop too
    assert main(["plan", held_still(tmp_path, 0.05), "--backend", "pinv"]) == 0  # warmed up
    scene = held_still(tmp_path, 100.0)
    estimate = RunEstimate.of(load_scene(scene))
    tracemalloc.start()  # NumPy reports its buffers to tracemalloc
    try:
        code = main(["plan", scene, "--backend", "pinv", "-o", str(tmp_path / "run.npz")])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert code == 0 and estimate.steps == 20_000
    assert 0.8 <= peak / estimate.nbytes <= 1.2, (peak, estimate.nbytes)
