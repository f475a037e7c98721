"""A user's project from a wheel: build collide2d's wheel, install it into a fresh virtualenv in a
temporary folder, and run the README's workflow there: `collide2d init`, `pytest --update-goldens`,
`pytest`, `collide2d check`. Slow (a fresh virtualenv compiles the kernels the example needs); CI
runs it."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow
# A wheel built already from this checkout (CI's release), used instead of building one here.
BUILT_WHEEL = "COLLIDE2D_TEST_WHEEL"


def run(args, cwd, env=None) -> subprocess.CompletedProcess:
    proc = subprocess.run(
        [str(a) for a in args], cwd=cwd, env=env, capture_output=True, text=True, timeout=900
    )
    assert proc.returncode == 0, f"{args}\n{proc.stdout}\n{proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def bin_dir(tmp_path_factory) -> Path:
    """collide2d's wheel, built from a copy of the checkout (the build leaves nothing in it), or
    the one BUILT_WHEEL names, installed with the test extra into a fresh virtualenv: its bin
    folder (one for the module's tests)."""
    tmp_path = tmp_path_factory.mktemp("wheel")
    wheel = os.environ.get(BUILT_WHEEL) or None
    if wheel is None:
        source = tmp_path / "source"
        ignore = shutil.ignore_patterns("__pycache__", "*.egg-info", "build")
        for part in ("collide2d", "engine", "runner"):
            shutil.copytree(ROOT / part, source / part, ignore=ignore)
        for part in ("pyproject.toml", "README.md"):
            shutil.copy(ROOT / part, source / part)
        pip = [sys.executable, "-m", "pip"]
        run([*pip, "wheel", "--no-deps", "-q", "-w", tmp_path / "w", source], tmp_path)
        (wheel,) = (tmp_path / "w").glob("collide2d-*.whl")
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=True)
    bin_dir = env_dir / "bin"
    run([bin_dir / "python", "-m", "pip", "install", "-q", f"{wheel}[test]"], tmp_path)
    return bin_dir


def test_init_then_pytest_and_check_in_a_fresh_virtualenv_from_the_wheel(tmp_path, bin_dir):

    project = tmp_path / "project"
    project.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("CI", "PYTHONPATH", "VIRTUAL_ENV")}
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    init = run([bin_dir / "collide2d", "init"], project, env)
    assert "pytest --update-goldens" in init.stdout
    assert (project / "scenarios" / "example.yaml").is_file()
    assert "[tool.collide2d]" in (project / "pyproject.toml").read_text()
    assert "out/" in (project / ".gitignore").read_text().splitlines()

    # no test file and no conftest: the plugin collects one golden test per scenario
    assert not list(project.rglob("test_*.py")) and not list(project.rglob("conftest.py"))
    blessed = run([bin_dir / "pytest", "--update-goldens", "-p", "no:cacheprovider"], project, env)
    assert "created   example:" in blessed.stdout and "1 passed" in blessed.stdout
    manifest = json.loads((project / "goldens" / "example" / "manifest.json").read_text())
    assert manifest["scenario"] == "example"
    checked = run([bin_dir / "pytest", "-v", "-p", "no:cacheprovider"], project, env)
    assert "scenarios/example.yaml::golden PASSED" in checked.stdout
    check = run([bin_dir / "collide2d", "check"], project, env)
    assert check.stdout.splitlines()[-1] == "1 passed, 0 failed"


def test_a_wheel_built_after_the_prebuild_runs_a_pile_compiled_with_nothing_to_compile(
    tmp_path, bin_dir
):
    """The kernels the wheel ships (docs/explanation/kernels.md#kernels-in-the-wheel): built
    after `python -m collide2d.runner.prebuild`, as CI builds it, the wheel holds the store, and
    a fresh virtualenv with an empty numba cache runs the gravity pile (stepped) and the bench's
    standard scene under the paper and exact models compiled, without compiling a kernel: the
    compile budget of a wheel's first run is zero."""
    store = ROOT / "engine" / "compiled-kernels" / "manifest.json"
    if not store.is_file():
        if os.environ.get("CI"):
            pytest.fail("CI runs the prebuild first: engine/compiled-kernels/ is missing")
        pytest.skip("no kernel store in this checkout: python -m collide2d.runner.prebuild")

    from collide2d.runner.bench.scenes import standard_scene
    from collide2d.runner.prebuild import pile_scene

    scenes = {"pile1000": pile_scene(1000, ticks=300)}
    scenes |= {f"standard {m}": standard_scene(300, m, ticks=30) for m in ("paper", "exact")}
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "COLLIDE2D_"))}
    env = {**env, "NUMBA_CACHE_DIR": str(tmp_path / "empty-cache")}
    env.pop("PYTHONPATH", None)
    for name, text in scenes.items():
        (tmp_path / "scene.yaml").write_text(text)
        command = [bin_dir / "collide2d", "run", "scene.yaml", "--out", "out", "--jit", "on"]
        run(command, tmp_path, env)
        (summary,) = (tmp_path / "out").glob("*/summary.json")
        found = json.loads(summary.read_text())
        assert found["kernels"] == "compiled" and found["compile_time_s"] == 0.0, (name, found)
        shutil.rmtree(tmp_path / "out")
    assert not list((tmp_path / "empty-cache").rglob("*.nbc"))
