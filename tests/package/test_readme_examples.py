"""The README's examples run after its install lines: each example line that needs an optional
extra names it on the same line, the "all of them" install line installs every one (each an
extra of pyproject.toml), and a command whose extra is missing stops at once with one line
saying what to install, before any work."""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

cli = importlib.import_module("dvqp.cli.main")  # the module (dvqp.cli.main is also its main)
ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text(encoding="utf-8")
EXTRAS = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"][
    "optional-dependencies"
]
NEEDS = {
    "plot": r"^dvqp plot ",
    "view": r"^dvqp view ",
    "retime": r"--retime",
    "console": r"^dvqp console ",
    "dask": r"--scheduler",
    "qpbenchmark": r"^qpbenchmark ",
}
"""The extra an example line needs, by what the line runs."""


def examples() -> list[str]:
    """The command lines of the README's examples (after "Then, for instance")."""
    block = README.split("Then, for instance")[1].split("```bash")[1].split("```")[0]
    return [line for line in block.splitlines() if line.strip()]


def test_each_example_line_names_the_extra_it_needs_and_one_line_installs_them_all() -> None:
    install = re.search(r"all of them: `pip install -e '\.\[([\w,]+)\]'`", README)
    assert install is not None
    everything = set(install.group(1).split(","))
    assert everything <= set(EXTRAS)
    needed = set()
    for line in examples():
        for extra, pattern in NEEDS.items():
            if re.search(pattern, line):
                assert f"dvqp[{extra}]" in line, line
                needed.add(extra)
    assert needed == set(NEEDS) and needed | {"solvers"} <= everything
    first = re.search(r"pip install -e '\.\[([\w,]+)\]' && dvqp compare", README)
    assert first is not None and {"solvers", "plot"} <= set(first.group(1).split(","))


def test_retime_without_toppra_stops_in_one_line_before_planning(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "toppra", None)  # import toppra: ImportError

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("planned before saying what is missing")

    monkeypatch.setattr(cli, "plan", never)
    scene = str(ROOT / "scenes" / "paper-two-inlets.toml")
    assert cli.main(["plan", scene, "--retime", "-o", "x.jt.json"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("dvqp: retiming needs toppra")
    assert err.endswith("pip install 'dvqp[retime]'\n")


def test_plot_without_matplotlib_stops_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from tests.runs import run

    saved = tmp_path / "paper.npz"
    run("paper-two-inlets", "daqp").save(saved)
    for name in ["matplotlib", *(m for m in sys.modules if m.startswith("matplotlib."))]:
        monkeypatch.setitem(sys.modules, name, None)  # imported or not: an ImportError
    assert cli.main(["plot", str(saved), "-o", str(tmp_path / "paper.png")]) == 2
    err = capsys.readouterr().err
    assert err == "dvqp: plotting needs matplotlib: pip install 'dvqp[plot]'\n"
    assert not (tmp_path / "paper.png").exists()
