"""Imports point down: no two modules of the package import each other, and none imports
another's private (underscore) names."""

from __future__ import annotations

import ast
from pathlib import Path

from fixture_files import ROOT

PACKAGE = ROOT / "colregs9_cli"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _package_of(path: Path) -> str:
    """The package that ``path``'s relative imports start from."""
    name = _module_name(path)
    return name if path.name == "__init__.py" else name.rsplit(".", 1)[0]


def _source_module(node: ast.ImportFrom, package: str) -> str:
    """The module a ``from … import`` reads from, a relative one resolved in ``package``."""
    if not node.level:
        return node.module or ""
    base = package.split(".")[: len(package.split(".")) - (node.level - 1)]
    return ".".join([*base, *([node.module] if node.module else [])])


def _imports(path: Path) -> set[str]:
    """The package modules ``path`` imports (relative imports resolved)."""
    package = _package_of(path)
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level:
            module = _source_module(node, package)
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


# The layers of docs/design.md §3 and what each may not import. The package root's modules
# (errors, config, geo, …) are the base every layer may use; the base imports no layer.
LAYERS = ("ais", "charts", "core", "jobs", "report")
FORBIDDEN: dict[str, frozenset[str]] = {
    "base": frozenset(LAYERS),
    "ais": frozenset({"core", "charts", "jobs", "report"}),
    "charts": frozenset({"core", "jobs", "report", "ais"}),
    "core": frozenset({"jobs", "report", "ais"}),
    "report": frozenset({"jobs", "ais"}),
    "jobs": frozenset(),
}
FACES = frozenset({"colregs9_cli.cli", "colregs9_cli.api", "colregs9_cli.__main__"})
MAX_MODULE_LINES = 800
MAX_FUNCTION_LINES = 120


def _layer(module: str) -> str | None:
    """The layer of a package module: ``ais`` … ``report``, ``base``, or None for the faces."""
    if module in FACES:
        return None
    parts = module.split(".")
    return parts[1] if len(parts) > 2 and parts[1] in LAYERS else "base"


def _all_imports(path: Path) -> set[str]:
    """Every package module ``path`` imports, at the top or inside a function or a
    TYPE_CHECKING block (a lazy import still ties the layers together)."""
    found = _imports(path)
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("colregs9_cli"))
    return {name for name in found if name.startswith("colregs9_cli")}


def test_imports_point_down_the_layers() -> None:
    broken = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = _module_name(path)
        layer = _layer(module)
        if layer is None:
            continue
        for imported in sorted(_all_imports(path)):
            target = _layer(imported)
            if target in FORBIDDEN[layer]:
                broken.append(f"{module} ({layer}) imports {imported} ({target})")
    assert broken == []


def test_the_contract_sees_a_forbidden_import() -> None:
    """The check above can fail: a core module importing a job is found."""
    assert _layer("colregs9_cli.core.pair") == "core"
    assert _layer("colregs9_cli.jobs.replay") in FORBIDDEN["core"]
    assert _layer("colregs9_cli.geo") == "base" and "core" in FORBIDDEN["base"]
    assert _layer("colregs9_cli.cli") is None


def _private_imports(tree: ast.AST, package: str) -> list[str]:
    """``module.name`` for each underscore name imported from a package module; dunders
    (``__version__``) are not private, and ``__future__`` is no package module."""
    found: list[str] = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        module = _source_module(node, package)
        if not module.startswith("colregs9_cli"):
            continue
        for alias in node.names:
            dunder = alias.name.startswith("__") and alias.name.endswith("__")
            if alias.name.startswith("_") and not dunder:
                found.append(f"{module}.{alias.name}")
    return found


def test_no_module_imports_another_modules_private_names() -> None:
    """A name that another module uses is part of its module's interface: it has no
    leading underscore."""
    found = [
        f"{_module_name(path)} imports {name}"
        for path in sorted(PACKAGE.rglob("*.py"))
        for name in _private_imports(ast.parse(path.read_text(encoding="utf-8")), _package_of(path))
    ]
    assert found == []


def test_the_contract_sees_a_private_import() -> None:
    """The check above can fail: an underscore name from a sibling module is found, and
    ``__future__``, dunders and other packages' names are let through."""
    source = (
        "from __future__ import annotations\n"
        "from .. import __version__\n"
        "from .read import _Features, read_features\n"
        "from colregs9_cli.geo import _private\n"
        "from numpy import _typing\n"
    )
    assert _private_imports(ast.parse(source), "colregs9_cli.charts") == [
        "colregs9_cli.charts.read._Features",
        "colregs9_cli.geo._private",
    ]


def test_no_module_or_function_is_too_long() -> None:
    """Modules up to 800 lines, functions up to 120; the CLI's commands are mostly option
    declarations, so only their bodies count."""
    too_long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        if text.count("\n") > MAX_MODULE_LINES:
            too_long.append(f"{path.name}: {text.count(chr(10))} lines")
        for node in ast.walk(ast.parse(text)):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            start = node.body[0].lineno if path.name == "cli.py" else node.lineno
            lines = (node.end_lineno or node.lineno) - start + 1
            if lines > MAX_FUNCTION_LINES:
                too_long.append(f"{path.name}:{node.lineno} {node.name}: {lines} lines")
    assert too_long == []
