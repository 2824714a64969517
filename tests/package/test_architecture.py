"""The package's shape: short functions, grouped subpackages, no import cycle (a module's length
is a guide, never a cap: ruff format owns the layout, nothing packs lines to meet a size)."""

from __future__ import annotations

import ast
import importlib
import pkgutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("dvqp", "solvers")
MAX_FUNCTION_LINES = 60
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


def test_at_most_fifteen_modules_sit_directly_in_dvqp() -> None:
    assert len(list((ROOT / "dvqp").glob("*.py"))) <= MAX_TOP_LEVEL_MODULES


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports_of(source: str, name: str, is_package: bool, modules: set[str]) -> set[str]:
    """The modules among ``modules`` that module ``name`` (its ``source``) imports ANYWHERE:
    at module level, inside functions and under ``if TYPE_CHECKING:``, absolute or relative.
    ``from a.b import c`` names the module ``a.b.c`` if there is one, else ``a.b`` (a
    package: its __init__). Importing ``a.b.c`` also runs the __init__ of the packages ``a``
    and ``a.b``: those count too, unless they contain the importing module (Python is then
    running them already)."""
    package = name if is_package else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parent, *([base] if base else [])])
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base)
    parents = {".".join(m.split(".")[:i]) for m in found for i in range(1, m.count(".") + 1)}
    own = {".".join(name.split(".")[:i]) for i in range(1, name.count(".") + 1)}
    return ((found | (parents - own)) & modules) - {name}


def import_graph(package: str) -> dict[str, set[str]]:
    """Module (packages' __init__ included) -> the modules of ``package`` it imports."""
    paths = modules(package)
    names = {module_name(p) for p in paths}
    graph = {
        module_name(p): imports_of(
            p.read_text(encoding="utf-8"), module_name(p), p.name == "__init__.py", names
        )
        for p in paths
    }
    if package == "solvers":  # the registry imports the direct adapters by name
        from solvers.registry import DIRECT

        graph["solvers.registry"] |= {f"solvers.{module}" for module, _ in DIRECT.values()}
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of ``graph`` (its first module repeated at the end), or None."""
    done: set[str] = set()

    def visit(path: list[str]) -> list[str] | None:
        for dep in sorted(graph.get(path[-1], ())):
            if dep in path:
                return [*path[path.index(dep) :], dep]
            if dep not in done and (cycle := visit([*path, dep])):
                return cycle
        done.add(path[-1])
        return None

    for node in sorted(graph):
        if node not in done and (cycle := visit([node])):
            return cycle
    return None


@pytest.mark.parametrize("package", PACKAGES)
def test_the_import_graph_has_no_cycle_counting_every_import(package: str) -> None:
    graph = import_graph(package)
    cycle = find_cycle(graph)
    assert cycle is None, " -> ".join(cycle or [])


def test_imports_in_functions_under_type_checking_and_relative_ones_count() -> None:
    source = (
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from dvqp.step import Stepper\n"
        "def f():\n    from ..proximity import measure\n    import dvqp.run.planning\n"
        "from . import band\n"
    )
    names = {module_name(p) for p in modules("dvqp")}
    found = imports_of(source, "dvqp.geometry.shapes.probe", False, names)
    assert found == {
        "dvqp.step",
        "dvqp.geometry.proximity",
        "dvqp.run.planning",
        "dvqp.run",
        "dvqp.geometry.shapes.band",
    }
    # a module of another package runs that package's __init__ first
    assert imports_of("from dvqp.cli.report import x", "dvqp.bench.a", False, names) == {
        "dvqp.cli.report",
        "dvqp.cli",
    }
    cycle = find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}})
    assert cycle == ["a", "b", "c", "a"]


def facade_imports(source: str, modules: set[str]) -> list[str]:
    """The imports in ``source`` (anywhere) that take a name from the facade ``dvqp/__init__``:
    ``import dvqp`` or ``from dvqp import X`` where ``dvqp.X`` is no module of the package."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [f"{node.lineno}: import dvqp" for a in node.names if a.name == "dvqp"]
        elif isinstance(node, ast.ImportFrom) and node.module == "dvqp" and not node.level:
            found += [
                f"{node.lineno}: from dvqp import {a.name}"
                for a in node.names
                if f"dvqp.{a.name}" not in modules
            ]
    return found


def test_no_module_of_the_package_imports_the_facade() -> None:
    names = {module_name(p) for p in modules("dvqp")}
    found = [
        f"{path.relative_to(ROOT)}:{entry}"
        for path in modules("dvqp")
        if module_name(path) != "dvqp"
        for entry in facade_imports(path.read_text(encoding="utf-8"), names)
    ]
    assert not found, found
    source = "import dvqp\nfrom dvqp import _validate\ndef f():\n    from dvqp import plan\n"
    assert facade_imports(source, names) == ["1: import dvqp", "4: from dvqp import plan"]


def test_the_bottom_package_imports_no_domain_module() -> None:
    graph = import_graph("dvqp")
    allowed = {"dvqp.errors", "dvqp.workspace"}
    for name, deps in graph.items():
        if name.startswith("dvqp.workspace"):
            assert all(d in allowed or d.startswith("dvqp.workspace.") for d in deps), name


def test_every_module_imports_on_its_own() -> None:
    for package in PACKAGES:
        pkg = importlib.import_module(package)
        for info in pkgutil.walk_packages(pkg.__path__, f"{package}."):
            importlib.import_module(info.name)


def test_solvers_contains_no_robotics() -> None:
    dvqp_modules = {module_name(p) for p in modules("dvqp")}
    for path in modules("solvers"):
        source = path.read_text(encoding="utf-8")
        assert not imports_of(source, module_name(path), False, dvqp_modules), path
