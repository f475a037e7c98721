"""Installed names: collide2d lives under `collide2d.*` and runs beside a user's own `engine/` and
`runner/` packages, from a wheel and from the development install alike."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "fig2_case1.yaml"


def user_project(tmp_path: Path) -> Path:
    """A folder with packages of its own called engine and runner, as many projects have."""
    project = tmp_path / "project"
    for name in ("engine", "runner"):
        (project / name).mkdir(parents=True)
        (project / name / "__init__.py").write_text(f"OWNER = 'user {name}'\n")
    return project


def run_beside(project: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    code = (
        "import engine, runner, collide2d.engine, collide2d.runner\n"
        "assert engine.OWNER == 'user engine' and runner.OWNER == 'user runner'\n"
        "assert not hasattr(collide2d.engine, 'OWNER')\n"
    )
    check = subprocess.run(
        [sys.executable, "-c", code], cwd=project, env=env, capture_output=True, text=True
    )
    assert check.returncode == 0, check.stderr
    return subprocess.run(
        [sys.executable, "-m", "collide2d", "run", str(SCENARIO), "--out", "out", "--quiet"],
        cwd=project,
        env=env,
        capture_output=True,
        text=True,
    )


def test_the_command_runs_in_a_folder_with_its_own_engine_and_runner(tmp_path):
    project = user_project(tmp_path)
    proc = run_beside(project)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((project / "out" / "fig2_case1" / "summary.json").read_text())
    assert summary["events"]["pair"] >= 1


def pip(*args: str) -> None:
    proc = subprocess.run([sys.executable, "-m", "pip", *args], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_a_wheel_installs_only_collide2d_and_runs_beside_a_users_packages(tmp_path):
    # built from a copy, so that the build leaves nothing in the checkout
    source = tmp_path / "source"
    ignore = shutil.ignore_patterns("__pycache__", "*.egg-info", "build")
    for part in ("collide2d", "engine", "runner"):
        shutil.copytree(ROOT / part, source / part, ignore=ignore)
    for part in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / part, source / part)
    wheels = tmp_path / "wheels"
    pip("wheel", "--no-deps", "-q", "-w", str(wheels), str(source))
    (wheel,) = wheels.glob("collide2d-*.whl")
    tops = {name.split("/")[0] for name in zipfile.ZipFile(wheel).namelist()}
    assert {t for t in tops if not t.endswith(".dist-info")} == {"collide2d"}
    names = zipfile.ZipFile(wheel).namelist()
    assert "collide2d/runner/data/paper_fifty_boxes.yaml" in names
    entry_points = (
        zipfile.ZipFile(wheel)
        .read(next(n for n in names if n.endswith("entry_points.txt")))
        .decode()
    )
    assert "[pytest11]" in entry_points and "collide2d.runner.golden.plugin" in entry_points

    site = tmp_path / "site"
    pip("install", "--no-deps", "-q", "--target", str(site), str(wheel))
    project = user_project(tmp_path)
    # the same source as plain Python: no kernels to compile for a fresh copy
    env = {**os.environ, "PYTHONPATH": str(site), "NUMBA_DISABLE_JIT": "1"}
    where = subprocess.run(
        [sys.executable, "-c", "import collide2d.engine as e; print(e.__file__)"],
        cwd=project,
        env=env,
        capture_output=True,
        text=True,
    )
    assert where.stdout.startswith(str(site)), where  # the wheel's copy, not the checkout
    proc = run_beside(project, env)
    assert proc.returncode == 0, proc.stderr
    assert (project / "out" / "fig2_case1" / "final.csv").exists()
