"""The package's shape: short functions, small modules, grouped subpackages, no import cycle."""

from __future__ import annotations

import ast
import importlib
import pkgutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("dvqp", "solvers")
MAX_FUNCTION_LINES = 60
MAX_MODULE_LINES = 300
MAX_TOP_LEVEL_MODULES = 15


def modules(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


def code_lines(node: ast.FunctionDef | ast.AsyncFunctionDef, source: list[str]) -> int:
    """Lines of a function's code: its span less its docstring, blank and comment lines."""
    body = node.body
    start = node.lineno
    if (
        body
        and isinstance(body[0], ast.Expr)
        and isinstance(body[0].value, ast.Constant)
        and isinstance(body[0].value.value, str)
    ):
        docstring = range(body[0].lineno, (body[0].end_lineno or body[0].lineno) + 1)
    else:
        docstring = range(0)
    count = 0
    for number in range(start, (node.end_lineno or start) + 1):
        text = source[number - 1].strip()
        if number in docstring or not text or text.startswith("#"):
            continue
        count += 1
    return count


def long_functions(path: Path) -> list[str]:
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    found = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = code_lines(node, lines)
            if n > MAX_FUNCTION_LINES:
                found.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n} lines)")
    return found


@pytest.mark.parametrize("package", PACKAGES)
def test_no_function_is_longer_than_sixty_lines_of_code(package: str) -> None:
    found = [entry for path in modules(package) for entry in long_functions(path)]
    assert not found, found


@pytest.mark.parametrize("package", PACKAGES)
def test_no_module_is_longer_than_three_hundred_lines(package: str) -> None:
    found = [
        f"{p.relative_to(ROOT)} ({n})"
        for p in modules(package)
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES
    ]
    assert not found, found


def test_at_most_fifteen_modules_sit_directly_in_dvqp() -> None:
    assert len(list((ROOT / "dvqp").glob("*.py"))) <= MAX_TOP_LEVEL_MODULES


def imports_of(path: Path, package: str) -> set[str]:
    """Modules of ``package`` imported by ``path`` at module level (not inside functions)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.split(".")[0] == package:
                found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == package)
    return found


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def test_the_import_graph_of_dvqp_modules_has_no_cycle() -> None:
    """Module-level imports between dvqp's modules (a package's __init__ re-exports excluded)."""
    graph: dict[str, set[str]] = {}
    for path in modules("dvqp"):
        if path.name == "__init__.py":
            continue
        name = module_name(path)
        graph[name] = {m for m in imports_of(path, "dvqp") if m != name}
    resolved = {
        name: {d for d in deps if d in graph} for name, deps in graph.items()
    }  # imports of a package's __init__ only re-export: ignored
    state: dict[str, int] = {}

    def visit(node: str, trail: list[str]) -> None:
        state[node] = 1
        for dep in sorted(resolved[node]):
            if state.get(dep) == 1:
                raise AssertionError(" -> ".join([*trail, node, dep]))
            if dep not in state:
                visit(dep, [*trail, node])
        state[node] = 2

    for node in sorted(resolved):
        if node not in state:
            visit(node, [])


def test_every_module_imports_on_its_own() -> None:
    for package in PACKAGES:
        pkg = importlib.import_module(package)
        for info in pkgutil.walk_packages(pkg.__path__, f"{package}."):
            importlib.import_module(info.name)


def test_solvers_contains_no_robotics() -> None:
    for path in modules("solvers"):
        assert not imports_of(path, "dvqp"), path
