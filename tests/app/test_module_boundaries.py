"""Module boundaries of app/ that import-linter's contracts (pyproject.toml) do not see: no module
uses another module's private (``_name``) names, and the dashboard's views get the dashboard
object instead of importing its module.  Static checks of the source (ast), no imports."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]  # the project (tests/app/)
APP_MODULES = sorted((ROOT / "app").rglob("*.py"))
# private names of other libraries that a module uses on purpose: (module, name) -> why
THIRD_PARTY = {
    ("app/dashboard/panel_fixes.py", "_update"): "Panel's markup update, patched (the module says why)",
    ("app/server/serve.py", "_exit"): "os._exit after a fatal error",
    ("app/server/serve.py", "_template_variables"): "Bokeh's document template variables",
}


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else path.as_posix()


def _own_private_names(tree: ast.AST) -> set[str]:
    """Private names a module defines itself: functions, classes, assignments, attributes it sets."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
    return {name for name in names if name.startswith("_")}


def _private_uses(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    own = _own_private_names(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in ("app", "model"):
            found += [f"line {node.lineno}: from {node.module} import {alias.name}"
                      for alias in node.names if alias.name.startswith("_")
                      and not alias.name.startswith("__")]
        elif (isinstance(node, ast.Attribute) and node.attr.startswith("_")
              and not node.attr.startswith("__")
              and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
              and node.attr not in own and (_relative(path), node.attr) not in THIRD_PARTY):
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def test_the_check_finds_a_private_name_of_another_module(tmp_path):
    """The check itself: a view reaching into the dashboard, a private import, a clean module."""
    view = tmp_path / "view.py"
    view.write_text("from app.results.plots import _figure\n"
                    "class View:\n"
                    "    def __init__(self, dashboard):\n"
                    "        self._own = dashboard._params_path\n"
                    "        self._own.strip()\n")
    assert [use.split(": ")[1] for use in _private_uses(view)] == [
        "from app.results.plots import _figure", "dashboard._params_path"]


@pytest.mark.parametrize("path", APP_MODULES, ids=_relative)
def test_no_module_uses_private_names_of_another(path):
    assert _private_uses(path) == []


def test_views_get_the_dashboard_instead_of_importing_it():
    views = [path for path in (ROOT / "app" / "dashboard").glob("*.py")
             if path.name not in ("dashboard.py", "__init__.py")]
    assert len(views) >= 6
    importers = []
    for path in views:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            modules = ([node.module or ""] if isinstance(node, ast.ImportFrom)
                       else [alias.name for alias in node.names] if isinstance(node, ast.Import)
                       else [])
            importers += [f"{path.name}: {module}" for module in modules
                          if module == "app.dashboard.dashboard"]
            if isinstance(node, ast.ImportFrom) and node.module == "app.dashboard":
                importers += [f"{path.name}: app.dashboard.{alias.name}" for alias in node.names
                              if alias.name == "dashboard"]
    assert importers == []
