"""The two lanes of a kernel (engine.jit): compiled by numba or interpreted, chosen per call.

A kernel runs its Python function in the interpreted lane and numba's dispatcher in the compiled
one; inside a compiled kernel the kernels it calls (plain, inline="always", overloaded) compile
with it; an interpreted lane never imports numba; a kernel pickles by name.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

from collide2d.engine import jit
from collide2d.engine.broadphase import METHODS, find_pairs, sweep_pairs
from collide2d.engine.picture.raster import _round_into, round_positions

COMPILING = os.environ.get("NUMBA_DISABLE_JIT", "0") in ("", "0")


def test_the_lane_is_set_for_a_block_and_restored():
    outer = jit.compiled()
    with jit.lane(not outer):
        assert jit.compiled() is (not outer)
        with jit.lane(outer):
            assert jit.compiled() is outer
        assert jit.compiled() is (not outer)
    assert jit.compiled() is outer


@pytest.mark.skipif(not COMPILING, reason="NUMBA_DISABLE_JIT: nothing compiles")
def test_a_compiled_call_runs_numbas_dispatcher_and_an_interpreted_one_the_function():
    pos = np.array([[0.5, -0.5], [2.4999999999999996, 1e300]])
    with jit.lane(False):
        interpreted = round_positions(pos)
    with jit.lane(True):
        compiled = round_positions(pos)
    assert _round_into.signatures, "the compiled lane did not go through numba"
    assert np.array_equal(interpreted, compiled)
    assert interpreted.tolist() == [[1, 0], [2, 2**40]]


@pytest.mark.skipif(not COMPILING, reason="NUMBA_DISABLE_JIT: nothing compiles")
def test_kernels_calling_inlined_and_overloaded_kernels_give_the_same_pairs_in_both_lanes():
    rng = np.random.default_rng(3)
    lo = rng.uniform(0, 200, (120, 2))
    hi = lo + rng.uniform(1, 25, (120, 2))
    movable = rng.random(120) < 0.8
    expected = sweep_pairs(lo, hi, ~movable)
    for method in METHODS.values():  # `find`'s overload picks the finder by a marker's type
        for compiled in (False, True):
            with jit.lane(compiled):
                got = find_pairs(method, lo, hi, movable, 30.0)
            assert np.array_equal(got, expected), (method, compiled)


def test_a_kernel_pickles_as_itself():
    assert pickle.loads(pickle.dumps(_round_into)) is _round_into


def test_an_interpreted_run_never_imports_numba(tmp_path):
    scenario = tmp_path / "s.yaml"
    scenario.write_text(
        "version: 1\nname: s\nworld: {width: 40, height: 30, fps: 10}\nticks: 20\n"
        "objects:\n  - {shape: box, size: 4, position: [2, 2], velocity: [30, 20]}\n"
        "  - {shape: circle, diameter: 6, position: [20, 10], velocity: [-20, 10]}\n"
        "output: {frames: [0, 20], gif: true, events: true}\n"
    )
    code = (
        "import sys\n"
        "from collide2d.runner.command.main import main\n"
        f"status = main(['run', {str(scenario)!r}, '--out', {str(tmp_path / 'out')!r}, "
        "'--quiet', '--jit', sys.argv[1]])\n"
        "print(status, 'numba' in sys.modules)\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("COLLIDE2D_JIT", "NUMBA_DISABLE_JIT")}
    for mode, loads_numba in (("auto", "False"), ("off", "False"), ("on", "True")):
        done = subprocess.run(
            [sys.executable, "-c", code, mode], capture_output=True, text=True, env=env
        )
        assert done.stdout.split() == ["0", loads_numba], (mode, done.stdout, done.stderr)


CALLER = """from collide2d.engine.jit import njit
from pkg.callee import g


@njit(cache=True)
def f(x):
    return g(x) + 1
"""
CALLEE = """from collide2d.engine.jit import njit


@njit(cache=True)
def g(x):
    return x * {factor}
"""


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_an_edit_of_a_called_kernels_file_alone_compiles_the_caller_afresh(tmp_path):
    # numba keeps a cached kernel while its own file is unchanged, with the kernels it calls
    # compiled into it; a kernel of collide2d is stale once any file of its package changed
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "caller.py").write_text(CALLER)
    env = dict(
        os.environ,
        COLLIDE2D_KERNEL_STORE="off",
        NUMBA_CACHE_DIR=str(tmp_path / "cache"),
        PYTHONPATH=str(tmp_path),
    )
    env.pop("COLLIDE2D_JIT", None)
    code = (
        "from numba.core import event\n"
        "compiled = []\n"
        "class Listen(event.Listener):\n"
        "    def on_start(self, ev): compiled.append(ev.data['dispatcher'].py_func.__name__)\n"
        "    def on_end(self, ev): pass\n"
        "event.register('numba:compile', Listen())\n"
        "from pkg.caller import f\n"
        "print(f(3), *sorted(compiled) or ['none'])\n"
    )

    def run() -> list[str]:
        done = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
        )
        return done.stdout.split()

    (package / "callee.py").write_text(CALLEE.format(factor=2))
    assert run() == ["7", "f", "g"]  # compiled
    assert run() == ["7", "none"]  # loaded from the cache
    (package / "callee.py").write_text(CALLEE.format(factor=3))
    assert run() == ["10", "f", "g"]  # compiled again, the caller too: its callee changed
    assert run() == ["10", "none"]


def test_a_source_that_cannot_be_read_still_gives_a_package_digest(tmp_path, monkeypatch):
    # a file the process may not read (another user's, say) must not stop a compiled run: its
    # size and time stand in for its text, so changing it still changes the digest
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "locked.py").write_text("y = 2\n")
    opened = open

    def refuse_locked(path, *args, **kwargs):
        if str(path).endswith("locked.py"):
            raise PermissionError(path)
        return opened(path, *args, **kwargs)

    monkeypatch.setattr("builtins.open", refuse_locked)
    before = jit._package_fingerprint.__wrapped__(str(tmp_path))
    (tmp_path / "locked.py").write_text("y = 22\n")
    assert jit._package_fingerprint.__wrapped__(str(tmp_path)) != before


def test_a_recording_block_collects_the_kernels_called_interpreted_nested_ones_too():
    rng = np.random.default_rng(3)
    lo = rng.uniform(0, 200, (60, 2))
    hi = lo + rng.uniform(1, 25, (60, 2))
    movable = np.ones(60, bool)
    with jit.lane(False), jit.recording() as called:
        round_positions(lo)
        find_pairs(METHODS["sweep"], lo, hi, movable, 30.0)
    assert _round_into in called
    names = {k.__name__ for k in called}
    assert len(names) >= 3, names  # find_pairs' kernels and the kernels they call
    kept = set(called)
    with jit.lane(False):
        round_positions(lo)  # no block open: nothing recorded
    assert called == kept
    if COMPILING:
        with jit.lane(True), jit.recording() as compiled_calls:
            find_pairs(METHODS["sweep"], lo, hi, movable, 30.0)
        assert compiled_calls == set()  # compiled calls are numba's: a run that switched stops
        # adding to what it needs


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="nothing compiles")
def test_readiness_says_cold_cached_or_compiled_and_an_empty_cache_is_seen_without_numba(
    tmp_path,
):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "caller.py").write_text(CALLER)
    (package / "callee.py").write_text(CALLEE.format(factor=2))
    env = dict(
        os.environ,
        COLLIDE2D_KERNEL_STORE="off",
        NUMBA_CACHE_DIR=str(tmp_path / "cache"),
        PYTHONPATH=str(tmp_path),
    )
    env.pop("COLLIDE2D_JIT", None)
    code = (
        "import sys\nfrom collide2d.engine import jit\nfrom pkg.caller import f\n"
        "empty = jit.cache_empty()\nloaded = 'numba' in sys.modules\n"
        "before = jit.readiness(f)\nf(3)\nprint(empty, loaded, before, jit.readiness(f))\n"
    )

    def run() -> list[str]:
        done = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True
        )
        return done.stdout.split()

    assert run() == ["True", "False", "cold", "compiled"]  # compiled, then cached on disk
    assert run() == ["False", "False", "cached", "compiled"]
