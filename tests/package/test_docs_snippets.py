"""Every Python snippet of the README and docs/ runs as written: each file's snippets in order,
in one fresh Python process and one namespace (a later snippet may use what an earlier one
made), in a fresh directory where ``scenes/`` and ``docs/`` are the repository's. The console's
pendant runs against a console this test starts, on the URL it printed."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.servers import serving

ROOT = Path(__file__).resolve().parents[2]
FILES = ("README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")))
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)
PENDANT_URL = "http://127.0.0.1:8765/?token=..."
"""The URL docs/console.md's pendant is written with: the line ``dvqp console`` prints."""

RUNNER = """
from pathlib import Path
namespace = {"__name__": "__snippet__"}
for i, code in enumerate(SNIPPETS):
    path = Path(f"snippet_{i}.py").resolve()  # a file of its own: numba's cache locates it
    path.write_text(code, encoding="utf-8")
    try:
        exec(compile(code, str(path), "exec"), namespace)
    except BaseException as exc:
        raise SystemExit(f"{NAME} snippet {i}: {type(exc).__name__}: {exc}") from exc
"""


def snippets(name: str) -> list[str]:
    return BLOCK.findall((ROOT / name).read_text(encoding="utf-8"))


def run_snippets(name: str, codes: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    script = f"SNIPPETS = {codes!r}\nNAME = {name!r}\n{RUNNER}"
    env = {"MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-c", script],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
        env={**__import__("os").environ, **env},
    )


@pytest.mark.parametrize("name", [f for f in FILES if snippets(f)])
def test_every_snippet_runs_as_written(name: str, tmp_path: Path) -> None:
    for folder in ("scenes", "docs"):
        (tmp_path / folder).symlink_to(ROOT / folder)
    codes = snippets(name)
    if any(PENDANT_URL in code for code in codes):
        pytest.importorskip("aiohttp")
        scene = str(ROOT / "scenes" / "paper-two-inlets.toml")
        argv = [sys.executable, "-m", "dvqp", "console", scene, "--port", "0"]
        with serving(argv, ROOT) as console:
            url = console.stdout.readline().strip() if console.stdout else ""
            assert url.startswith("http://127.0.0.1:"), url
            done = run_snippets(name, [c.replace(PENDANT_URL, url) for c in codes], tmp_path)
    else:
        done = run_snippets(name, codes, tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]


def test_a_snippet_that_does_not_run_is_caught(tmp_path: Path) -> None:
    done = run_snippets("broken.md", ["x = 1\n", "print(y)\n"], tmp_path)
    assert done.returncode != 0 and "broken.md snippet 1: NameError" in done.stderr
