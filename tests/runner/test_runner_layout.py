"""The runner's layout: a package or module per concern, each package saying in its docstring what
it is for and what it may import, the imports keeping to that and running one way, small modules in
small folders, and no two names told apart only by a suffix across concerns (docs/architecture.md,
docs/explanation/design.md).

Imports are read from the sources (every import statement, those inside functions included), so
these tests load no module of the project.
"""

from __future__ import annotations

import ast
import itertools
import re
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
RUNNER = ROOT / "runner"
MAX_LINES = 600
# "About 15" modules to a folder: at most this many besides its __init__.py.
MAX_MODULES = 16

# What each concern of the runner may import: the engine, the modules at the top of runner/ and
# its packages, each only those below it. The package docstrings say the same (checked below).
BELOW_COMMAND = {"engine", "lanes", "compiling", "scenario", "output", "run"}
MAY_IMPORT = {
    "compilecost": {"engine"},
    "lanes": {"engine", "compilecost", "compiling"},
    "compiling": {"engine"},
    "scenario": {"engine", "lanes"},
    "output": {"engine", "scenario"},
    "interrupt": {"output"},
    "run": {"engine", "lanes", "compiling", "scenario", "output", "interrupt"},
    "command": BELOW_COMMAND | {"interrupt", "compilecost"},
    "stress": BELOW_COMMAND | {"command"},
    "bench": BELOW_COMMAND | {"command"},
    "sweep": BELOW_COMMAND | {"command", "bench", "interrupt"},
    "golden": BELOW_COMMAND | {"command", "sweep"},
    "prebuild": {"engine", "command", "bench"},
    "__main__": {"command"},
}
# The packages whose docstrings also name each of their modules.
MAPPED = ("scenario", "output", "command")


def module_name(path: Path, folder: Path, package: str) -> str:
    parts = path.relative_to(folder).with_suffix("").parts
    return ".".join((package, *parts[:-1]) if parts[-1] == "__init__" else (package, *parts))


def sources(folder: Path, package: str) -> dict[str, Path]:
    return {module_name(p, folder, package): p for p in sorted(folder.rglob("*.py"))}


RUNNER_MODULES = sources(RUNNER, "collide2d.runner")
KNOWN = set(RUNNER_MODULES) | set(sources(ROOT / "engine", "collide2d.engine"))


def imported(path: Path) -> set[str]:
    """The project's modules an import statement of the file names: `from a import b` names a.b
    when that is a module, else a. (`main` loads the commands' packages by name, with importlib:
    not an import statement.)"""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            assert not node.level, f"{path}:{node.lineno}: a relative import, unchecked here"
            for alias in node.names:
                full = f"{node.module}.{alias.name}"
                names.add(full if full in KNOWN else node.module)
    return names & KNOWN


IMPORTS = {name: imported(path) - {name} for name, path in RUNNER_MODULES.items()}


def concern(module: str) -> str:
    """"engine" for the engine's modules, else the runner's package or top module holding it."""
    parts = module.split(".")
    if parts[1] == "engine":
        return "engine"
    return parts[2] if len(parts) > 2 else "runner"


def docstring(package: str) -> str:
    doc = ast.get_docstring(ast.parse((RUNNER / package / "__init__.py").read_text("utf-8")))
    assert doc, f"runner/{package}/__init__.py has no docstring"
    return doc


def named_concerns(text: str) -> set[str]:
    """The concerns a text names in backticks: `collide2d.engine`, `runner.X` (or
    `collide2d.runner.X...`)."""
    found = set()
    for name in re.findall(r"`([\w.]+)`", text):
        parts = name.removeprefix("collide2d.").split(".")
        if parts[0] == "engine":
            found.add("engine")
        elif parts[0] == "runner" and len(parts) > 1:
            found.add(parts[1])
    return found


PACKAGES = sorted(p.parent.name for p in RUNNER.glob("*/__init__.py"))


@pytest.mark.parametrize("package", PACKAGES)
def test_each_package_says_its_role_and_exactly_what_it_may_import(package):
    assert package in MAY_IMPORT, f"runner/{package}/ has no import rule here"
    rules = [p for p in docstring(package).split("\n\n") if p.startswith("It may import")]
    assert len(rules) == 1, f"runner/{package}/__init__.py: no 'It may import' paragraph"
    assert named_concerns(rules[0]) == MAY_IMPORT[package]


def test_the_runner_docstring_names_every_package_and_top_module():
    doc = ast.get_docstring(ast.parse((RUNNER / "__init__.py").read_text("utf-8")))
    named = set(re.findall(r"`(\w+)`", doc))
    assert set(MAY_IMPORT) - {"__main__"} - named == set()


@pytest.mark.parametrize("package", MAPPED)
def test_the_package_docstring_names_each_of_its_modules(package):
    named = set(re.findall(r"`(\w+)`", docstring(package)))
    modules = {p.stem for p in (RUNNER / package).glob("*.py")} - {"__init__"}
    assert modules - named == set()


def test_every_import_keeps_to_the_rules():
    assert set(MAY_IMPORT) == {concern(name) for name in RUNNER_MODULES} - {"runner"}
    broken = sorted(
        (name, other)
        for name, names in IMPORTS.items()
        for other in names
        if concern(other) != concern(name)
        and concern(name) != "runner"
        and concern(other) not in MAY_IMPORT[concern(name)]
    )
    assert broken == []


def test_the_rules_run_one_way():
    """No concern may import, through others, one that may import it: the rules have an order."""
    order: list[str] = []
    left = dict(MAY_IMPORT)
    while left:
        ready = [c for c, below in left.items() if below - {"engine"} <= set(order)]
        assert ready, f"the rules of {sorted(left)} import each other"
        order += ready
        for c in ready:
            del left[c]


def test_no_import_cycle_among_runner_modules():
    state: dict[str, int] = {}
    cycles = []

    def visit(name: str, path: list[str]) -> None:
        state[name] = 1
        for other in sorted(IMPORTS[name] & set(RUNNER_MODULES)):
            if state.get(other) == 1:
                cycles.append(path[path.index(other) :] + [other])
            elif other not in state:
                visit(other, [*path, other])
        state[name] = 2

    for name in RUNNER_MODULES:
        if name not in state:
            visit(name, [name])
    assert cycles == []


def test_no_runner_module_is_past_the_line_limit():
    long = {
        name: n
        for name, path in RUNNER_MODULES.items()
        if (n := len(path.read_text(encoding="utf-8").splitlines())) > MAX_LINES
    }
    assert long == {}


@pytest.mark.parametrize("top", ["runner", "engine"])
def test_no_folder_is_past_about_15_modules(top):
    folder = ROOT / top
    crowded = {
        str(d.relative_to(ROOT)): n
        for d in (folder, *(p for p in folder.rglob("*") if p.is_dir()))
        if (n := len([p for p in d.glob("*.py") if p.name != "__init__.py"])) > MAX_MODULES
    }
    assert crowded == {}


def test_names_told_apart_only_by_a_suffix_share_a_concern():
    """`run` and `runs`, `report` and `reportpage`: a name that is another plus a suffix reads as
    a part of it, so the two live in one package."""
    modules = [(p.stem, concern(n)) for n, p in RUNNER_MODULES.items() if p.stem != "__init__"]
    pairs = sorted(
        (a, ca, b, cb)
        for (a, ca), (b, cb) in itertools.permutations(modules, 2)
        if a != b and b.startswith(a) and ca != cb
    )
    assert pairs == []


def test_every_runner_package_installs():
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    packages = {name for name, path in RUNNER_MODULES.items() if path.name == "__init__.py"}
    assert packages - set(setuptools["packages"]) == set()
