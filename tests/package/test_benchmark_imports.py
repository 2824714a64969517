"""A benchmark run as ``python benchmarks/<name>.py`` measures this checkout's packages."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_a_benchmark_imports_the_checkouts_dvqp_ahead_of_an_installed_one(tmp_path: Path) -> None:
    # An installed "dvqp" that is not this checkout's: first on the path after the script's
    # folder, as site-packages would be.
    fake = tmp_path / "site" / "dvqp"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('the installed copy was imported')\n")
    probe = tmp_path / "probe.py"
    probe.write_text(
        "import sys\n"
        f"sys.path[0] = {str(ROOT / 'benchmarks')!r}\n"
        f"sys.path.insert(1, {str(tmp_path / 'site')!r})\n"
        "import checkout  # noqa: F401\n"
        "import dvqp\n"
        "print(dvqp.__file__)\n"
    )
    done = subprocess.run(
        [sys.executable, str(probe)], capture_output=True, text=True, cwd=tmp_path, check=False
    )
    assert done.returncode == 0, done.stderr
    assert Path(done.stdout.strip()).resolve() == ROOT / "dvqp" / "__init__.py"


def test_every_benchmark_imports_checkout_before_the_packages() -> None:
    for script in sorted((ROOT / "benchmarks").glob("*.py")):
        if script.name == "checkout.py":
            continue
        lines = script.read_text().splitlines()
        imports = [i for i, line in enumerate(lines) if line.startswith(("import ", "from "))]
        packages = [i for i in imports if lines[i].split()[1].split(".")[0] in {"dvqp", "solvers"}]
        if not packages:  # it runs dvqp in fresh processes (startup.py, bench_scaling.py)
            continue
        first = packages[0]
        assert any(
            lines[i].startswith(("import checkout", "from checkout import"))
            for i in imports
            if i < first
        ), script
