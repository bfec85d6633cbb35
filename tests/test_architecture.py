"""The house's rules that import-linter's contracts (pyproject.toml) do not state: no import circle
among the modules of ``model`` and ``app``, few modules directly in ``model/`` (the rest in
wings), no module too long to read (docs/architecture.md)."""

from __future__ import annotations

import sys

from conftest import ROOT

MAX_MODULES_DIRECTLY_IN_MODEL = 6
MAX_LINES = 700


def _cycles(graph) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        on_stack.add(module)
        for other in graph.find_modules_directly_imported_by(module):
            if not other.startswith(("model", "app")):
                continue
            if other not in index:
                visit(other)
                low[module] = min(low[module], low[other])
            elif other in on_stack:
                low[module] = min(low[module], index[other])
        if low[module] == index[module]:
            component = []
            while True:
                other = stack.pop()
                on_stack.discard(other)
                component.append(other)
                if other == module:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for module in sorted(graph.modules):
        if module.startswith(("model", "app")) and module not in index:
            visit(module)
    return found


def test_no_import_circles():
    import grimp  # installed with import-linter (the test extra)
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    assert _cycles(grimp.build_graph("model", "app")) == []


def _long_modules(root, packages=("model", "app"), limit: int = MAX_LINES) -> dict[str, int]:
    """{path relative to ``root``: line count} of the ``.py`` modules under ``packages`` with more
    than ``limit`` lines."""
    found = {}
    for package in packages:
        for path in sorted((root / package).rglob("*.py")):
            count = len(path.read_text(encoding="utf-8").splitlines())
            if count > limit:
                found[path.relative_to(root).as_posix()] = count
    return found


def test_no_module_too_long():
    """No module of ``model`` or ``app`` has more than MAX_LINES lines: a longer one is split
    along a seam (docs/architecture.md)."""
    assert _long_modules(ROOT) == {}


def test_the_length_check_finds_a_long_module(tmp_path):
    (tmp_path / "model" / "wing").mkdir(parents=True)
    (tmp_path / "app").mkdir()
    (tmp_path / "model" / "wing" / "long.py").write_text("x = 1\n" * (MAX_LINES + 1))
    (tmp_path / "model" / "wing" / "limit.py").write_text("x = 1\n" * MAX_LINES)
    (tmp_path / "app" / "notes.txt").write_text("x\n" * (MAX_LINES + 1))
    assert _long_modules(tmp_path) == {"model/wing/long.py": MAX_LINES + 1}


def test_model_in_wings():
    direct = sorted(p.name for p in (ROOT / "model").glob("*.py"))
    assert len(direct) <= MAX_MODULES_DIRECTLY_IN_MODEL, direct


def test_the_circle_check_finds_a_circle():
    import grimp
    graph = grimp.ImportGraph()
    for importer, imported in (("app.a", "app.b"), ("app.b", "app.c"), ("app.c", "app.a"),
                               ("app.c", "model.d")):
        graph.add_import(importer=importer, imported=imported)
    assert _cycles(graph) == [["app.a", "app.b", "app.c"]]
