"""The engine's layout: each model is a package holding what only it uses, the modules at the top
of engine/ are shared, and the imports between them run one way (docs/architecture.md,
docs/explanation/design.md).

Imports are read from the sources (every import statement, those inside functions included), so
these tests load no kernel.
"""

from __future__ import annotations

import ast
import importlib
import sys
from pathlib import Path

import pytest

from collide2d.engine.models import MODEL_NAMES, make
from collide2d.engine.world import Bodies, WorldSpec

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
ENGINE = ROOT / "engine"
MAX_LINES = 600


def module_name(path: Path, folder: Path, package: str) -> str:
    parts = path.relative_to(folder).with_suffix("").parts
    return ".".join((package, *parts[:-1]) if parts[-1] == "__init__" else (package, *parts))


def sources(folder: Path, package: str) -> dict[str, Path]:
    return {module_name(p, folder, package): p for p in sorted(folder.rglob("*.py"))}


def imported(path: Path) -> set[str]:
    """Every module name an import statement of the file names (`from a import b`: a and a.b)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


ENGINE_MODULES = sources(ENGINE, "collide2d.engine")
RUNNER_MODULES = sources(ROOT / "runner", "collide2d.runner")


def imports_within(modules: dict[str, Path], known: dict[str, Path]) -> dict[str, set[str]]:
    return {name: (imported(path) & set(known)) - {name} for name, path in modules.items()}


ENGINE_IMPORTS = imports_within(ENGINE_MODULES, ENGINE_MODULES)


def concern(module: str) -> str:
    """Which part of the project a module belongs to: a model's name, "shared" (the top of the
    engine and the models' own package), or "runner"."""
    parts = module.split(".")
    if parts[1] == "runner":
        return "runner"
    if parts[2:3] == ["models"] and len(parts) > 3:
        return parts[3]
    return "shared"


@pytest.mark.parametrize("name", MODEL_NAMES)
def test_each_model_is_a_package_that_make_builds_by_name(name):
    package = ENGINE / "models" / name
    init = package / "__init__.py"
    assert init.is_file(), f"engine/models/{name}/ is not a package"
    assert ast.get_docstring(ast.parse(init.read_text(encoding="utf-8")))
    module = importlib.import_module(f"collide2d.engine.models.{name}")
    world, bodies = WorldSpec(40, 20, 10), Bodies.boxes([[2, 5], [24, 5]], 6, [[40, 0], [-30, 0]])
    assert type(make(name, world, bodies)) is module.Model


def test_what_only_one_model_uses_lives_in_that_models_package():
    users: dict[str, set[str]] = {name: set() for name in ENGINE_MODULES}
    runner_imports = imports_within(RUNNER_MODULES, ENGINE_MODULES)
    for importer, names in (*ENGINE_IMPORTS.items(), *runner_imports.items()):
        for name in names:
            users[name].add(concern(importer))
    loose = {
        name: sorted(by)
        for name, by in users.items()
        if concern(name) == "shared" and len(by) == 1 and next(iter(by)) in MODEL_NAMES
    }
    assert loose == {}


def test_the_shared_modules_import_no_model_and_no_model_imports_another():
    crossing = {
        (name, other)
        for name, names in ENGINE_IMPORTS.items()
        for other in names
        if concern(other) in MODEL_NAMES and concern(other) != concern(name)
    }
    assert crossing == set()


def test_the_engine_imports_nothing_of_the_runner():
    assert {
        name
        for name, path in ENGINE_MODULES.items()
        if any(n == "collide2d.runner" or n.startswith("collide2d.runner.") for n in imported(path))
    } == set()


def test_no_import_cycle_in_the_engine():
    state: dict[str, int] = {}
    cycles = []

    def visit(name: str, path: list[str]) -> None:
        state[name] = 1
        for other in sorted(ENGINE_IMPORTS[name]):
            if state.get(other) == 1:
                cycles.append(path[path.index(other) :] + [other])
            elif other not in state:
                visit(other, [*path, other])
        state[name] = 2

    for name in ENGINE_MODULES:
        if name not in state:
            visit(name, [name])
    assert cycles == []


def test_no_engine_module_is_past_the_line_limit():
    long = {
        name: n
        for name, path in ENGINE_MODULES.items()
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert long == {}


def test_every_engine_package_installs():
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(setuptools["packages"])
    packages = {name for name, path in ENGINE_MODULES.items() if path.name == "__init__.py"}
    assert packages - listed == set()
