"""Imports point down: no two modules of the package import each other."""

from __future__ import annotations

import ast
from pathlib import Path

from fixture_files import ROOT

PACKAGE = ROOT / "colregs9_cli"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """The package modules ``path`` imports (relative imports resolved)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
            module = ".".join([*base, *([node.module] if node.module else [])])
            found.add(module)
            found.update(f"{module}.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("colregs9_cli"):
            found.add(node.module or "")
    return found


def test_no_two_modules_import_each_other() -> None:
    modules = {_module_name(p): _imports(p) for p in PACKAGE.rglob("*.py")}
    assert len(modules) > 40
    mutual = sorted(
        (a, b)
        for a, deps in modules.items()
        for b in deps
        if b in modules and a in modules[b] and a < b
    )
    assert mutual == []
