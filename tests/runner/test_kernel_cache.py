"""The kernel cache never crashes a command: sequences of commands from an empty numba cache, each
in a process of its own as a user runs them, and every later command still works; a command or a
sweep's worker that dies of a fatal signal says which, and how to clear the cache."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent
NO_JIT = os.environ.get("NUMBA_DISABLE_JIT") == "1"

# Under the paper model a crowded scene finds its pairs with the cells broad phase and a sparse one
# with the sweep (engine.broadphase.choose): the kernel that steps the model takes the finder in
# its signature, so the second scene compiles a second specialisation of it, calling the parallel
# stages the first scene compiled and cached.
DENSE = """version: 1
name: dense
world: {width: 320, height: 240, fps: 60}
model: paper
ticks: 30
generate:
  - {count: 300, shape: box, size: 8, speed: {min: 20, max: 80}, seed: 3}
output: {frames: [], gif: false, events: false}
"""
SPARSE = """version: 1
name: sparse
world: {width: 2000, height: 2000, fps: 60}
model: paper
ticks: 30
generate:
  - {count: 60, shape: box, size: 4, speed: {min: 20, max: 80}, seed: 3}
output: {frames: [], gif: false, events: false}
golden: {frames: [0, 30]}
"""


def _collide2d(*args, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(BIN / "collide2d"), *args], cwd=cwd, env=env, capture_output=True, text=True,
        timeout=600,
    )  # fmt: skip


@pytest.mark.slow
@pytest.mark.skipif(NO_JIT, reason="nothing compiles")
def test_runs_of_a_dense_then_a_sparse_scene_leave_a_cache_later_commands_load(tmp_path):
    project = tmp_path / "project"
    (project / "scenarios").mkdir(parents=True)
    (project / "pyproject.toml").write_text('[project]\nname = "p"\n\n[tool.collide2d]\n')
    (project / "scenarios" / "sparse.yaml").write_text(SPARSE)
    (tmp_path / "dense.yaml").write_text(DENSE)
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("COLLIDE2D_JIT", None)
    env.pop("CI", None)  # the sequence blesses, which CI refuses
    out = str(tmp_path / "out")
    commands = [
        ("run", str(tmp_path / "dense.yaml"), "--jit", "on", "--out", out),
        ("run", "scenarios/sparse.yaml", "--jit", "on", "--out", out),
        # these load the sparse scene's kernel first, with no run's thread setting before it
        ("bless", "--jit", "on"),
        ("check", "--jit", "on"),
    ]
    for command in commands:
        done = _collide2d(*command, cwd=project, env=env)
        assert done.returncode == 0, (command, done.returncode, done.stderr)
    assert done.stdout.splitlines()[-1] == "1 passed, 0 failed"


# `collide2d run` whose run calls a kernel that writes far past its array's end
CRASHING_RUN = """
import sys
import numpy as np
from collide2d.engine.jit import njit
from collide2d.runner import run
from collide2d.runner.command import main as cli

@njit
def poke(a, i):
    a[i] = 1.0

def crash(*args, **kwargs):
    poke(np.zeros(1), 1 << 40)

run.write_run = crash  # the run path of `collide2d run` (collide2d.run)
sys.argv = ["collide2d", "run", "--out", "out"]
sys.exit(cli.main())
"""


@pytest.mark.skipif(NO_JIT, reason="nothing compiles")
@pytest.mark.skipif(not os.path.exists("/bin/sh"), reason="the watcher is a POSIX shell")
def test_a_command_that_dies_in_a_kernel_names_the_signal_and_the_cache_to_clear(tmp_path):
    cache = tmp_path / "kernel cache"
    env = dict(os.environ, COLLIDE2D_KERNEL_STORE="off", NUMBA_CACHE_DIR=str(cache))
    env.pop("PYTHONFAULTHANDLER", None)
    done = subprocess.run(
        [sys.executable, "-c", CRASHING_RUN], cwd=tmp_path, env=env, capture_output=True,
        text=True, timeout=300,
    )  # fmt: skip
    assert done.returncode == -signal.SIGSEGV
    first, *rest = done.stderr.splitlines()
    assert first.startswith("collide2d: error: the process died of SIGSEGV in a compiled kernel")
    assert f"NUMBA_CACHE_DIR ({cache}): rm -rf '{cache}'" in first
    assert "Fatal Python error: Segmentation fault" in rest
    assert any("in crash" in line for line in rest)  # the traceback follows, naming the caller


def test_a_command_that_ends_normally_or_by_an_error_says_nothing_more(tmp_path):
    env = dict(os.environ)
    env.pop("PYTHONFAULTHANDLER", None)
    (tmp_path / "bad.yaml").write_text("version: 1\nworld: {width: -1}\n")
    bad = _collide2d("validate", str(tmp_path / "bad.yaml"), cwd=tmp_path, env=env)
    assert bad.returncode == 2 and bad.stderr.startswith(f"{tmp_path / 'bad.yaml'}:2:")
    assert "died of" not in bad.stderr and "Fatal Python error" not in bad.stderr
    good = _collide2d("run", "--out", str(tmp_path / "out"), "--quiet", cwd=tmp_path, env=env)
    assert (good.returncode, good.stderr) == (0, "")


WORKER = """
import ctypes, sys
from collide2d.runner.command import crashwatch
crashwatch.record_in_worker()
if sys.argv[1] == "crash":
    ctypes.string_at(0)
"""
ROWS = """
import sys
from distributed import KilledWorker
from collide2d.runner.sweep.worker import error_figures
for since in sys.argv[1:]:
    died = KilledWorker("collide2d-sweep-0", "tcp://127.0.0.1:1", 3)  # (task, last worker, tries)
    print(error_figures(died, since=float(since))["note"])
"""


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="the records' folder is a POSIX user's")
def test_a_worker_that_dies_of_a_signal_gives_its_rows_the_reason(tmp_path):
    pytest.importorskip("distributed")
    env = dict(
        os.environ,
        COLLIDE2D_KERNEL_STORE="off",
        TMPDIR=str(tmp_path),
        NUMBA_CACHE_DIR=str(tmp_path / "cache"),
    )
    env.pop("PYTHONFAULTHANDLER", None)

    def python(code: str, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-c", code, *args], env=env, capture_output=True, text=True,
            timeout=120,
        )  # fmt: skip

    began = time.time() - 1
    assert python(WORKER, "end").returncode == 0
    assert python(WORKER, "crash").returncode == -signal.SIGSEGV
    rows = python(ROWS, str(began), str(time.time() + 60))
    assert rows.returncode == 0, rows.stderr
    told, stale = rows.stdout.splitlines()
    assert told.startswith("its worker died of SIGSEGV (a bug); if it happens again, clear")
    assert f"rm -rf {tmp_path / 'cache'}" in told
    # no record since the sweep began: what is known, and the cache to clear if a kernel crashed
    assert stale.startswith("its worker died on every try (killed by a signal, or out of memory)")
    assert f"rm -rf {tmp_path / 'cache'}" in stale
    # one record is left: the crash's; the worker that ended well left none once it was gone
    (folder,) = tmp_path.glob("collide2d-crashes-*")
    (record,) = folder.iterdir()
    assert record.read_text().startswith("Fatal Python error: Segmentation fault")
