"""One way through the three import packages (docs/architecture.md): `collide2d` (the public API:
`api`, `arguments`, `testing`, `python -m collide2d`) sits on top of `collide2d.runner`, which sits
on top of `collide2d.engine`; no module imports one above its own. Imports are read from the
sources (every import statement, those inside functions included): these tests load nothing."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# package -> (its folder in the repository, the packages above it, which it never imports)
LAYERS = {
    "collide2d": (ROOT / "collide2d", ()),
    "collide2d.runner": (ROOT / "runner", ("collide2d",)),
    "collide2d.engine": (ROOT / "engine", ("collide2d", "collide2d.runner")),
}
API = {p.stem for p in (ROOT / "collide2d").glob("*.py")} - {"__init__"}


def imports(path: Path) -> set[str]:
    """The modules the import statements of `path` name (`from a import b`: a, and a.b)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def layer_of(name: str) -> str | None:
    """The package of LAYERS a module name belongs to (`collide2d` itself: the API's modules and
    the package's own names such as `__version__`); None outside collide2d."""
    for package in ("collide2d.runner", "collide2d.engine"):
        if name == package or name.startswith(package + "."):
            return package
    if name == "collide2d" or name.startswith("collide2d."):
        return "collide2d"
    return None


@pytest.mark.parametrize("package", LAYERS)
def test_no_module_imports_a_package_above_its_own(package):
    folder, above = LAYERS[package]
    wrong = {}
    for path in sorted(folder.rglob("*.py")):
        upward = {name for name in imports(path) if layer_of(name) in above}
        if upward:
            wrong[str(path.relative_to(ROOT))] = sorted(upward)
    assert wrong == {}


def test_the_layers_are_told_apart_by_name():
    assert layer_of("collide2d") == layer_of("collide2d.api") == "collide2d"
    assert layer_of("collide2d.__version__") == "collide2d"
    assert layer_of("collide2d.runner.golden.cli") == "collide2d.runner"
    assert layer_of("collide2d.engine.jit") == "collide2d.engine"
    assert layer_of("numpy") is None
    assert API >= {"api", "arguments", "testing"}
