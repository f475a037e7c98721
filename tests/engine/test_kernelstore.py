"""The kernel store (engine/kernelstore.py, docs/explanation/kernels.md#kernels-in-the-wheel): the
kernels a wheel ships, compiled by the prebuild for a generic CPU, load in a process that would
otherwise compile them, on a machine whose numba cache is empty; a store written for other
sources, another Python or another numba is never read; `COLLIDE2D_KERNEL_STORE=off` turns it off.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

from collide2d.engine import kernelstore

ROOT = Path(__file__).resolve().parents[2]

# A child process with the store moved to STORE (argv[1]): in "build" it compiles a kernel into
# the store and writes the manifest; else it calls the kernel and says whether numba compiled it,
# and where the code came from.
CHILD = """
import json, sys
from collide2d.engine import kernelstore
kernelstore.STORE = sys.argv[1]
kernelstore.manifest.cache_clear()
from collide2d.engine import jit
from collide2d.engine.contact import box_penetration
from numba.core import event
compiled = []
class Listen(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__qualname__)
    def on_end(self, ev):
        pass
jit.numba_module()
event.register("numba:compile", Listen())
answer = box_penetration(0.0, 0.0, 10.0, 10.0, 4.0, 6.0)
if sys.argv[2] == "build":
    from numba.core.registry import cpu_target
    kernelstore.write_manifest(cpu_target.target_context.codegen().magic_tuple(), 1)
print(json.dumps({"answer": list(answer), "compiled": compiled,
                  "available": kernelstore.available()}))
"""


def child(store: Path, what: str, cache: Path, **env) -> dict:
    environment = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    environment.pop(kernelstore.SWITCH, None)
    environment.update(NUMBA_CACHE_DIR=str(cache), COLLIDE2D_JIT="on", **env)
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(store), what],
        capture_output=True,
        text=True,
        env=environment,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.splitlines()[-1])


def test_a_kernel_the_prebuild_compiled_loads_from_the_store_where_numba_would_compile(tmp_path):
    store = tmp_path / "store"
    built = child(
        store,
        "build",
        tmp_path / "build-cache",
        NUMBA_CPU_NAME="generic",
        **{kernelstore.BUILDING: "1"},
    )
    assert "box_penetration" in built["compiled"]
    (index,) = (store / "collide2d.engine.contact").glob("contact.box_penetration-*.nbi")
    manifest = json.loads((store / kernelstore.MANIFEST).read_text())
    assert manifest["magic"][1:] == ["generic", ""]  # no CPU name or feature of this machine

    # a machine with an empty numba cache: nothing compiles, the answer is the same
    loaded = child(store, "run", tmp_path / "empty-cache")
    assert loaded["available"] and loaded["compiled"] == []
    assert loaded["answer"] == built["answer"]
    assert not any((tmp_path / "empty-cache").rglob("*.nbc"))

    # turned off, the same kernel compiles into numba's own cache
    off = child(store, "run", tmp_path / "off-cache", **{kernelstore.SWITCH: "off"})
    assert not off["available"] and "box_penetration" in off["compiled"]
    assert off["answer"] == built["answer"]
    assert index.is_file()  # read, never written, by a user's process


@pytest.mark.parametrize(
    "stale",
    [
        {"fingerprint": "0" * 64},
        {"python": "py27"},
        {"numba": "0.1.0"},
        {"magic": None},
    ],
    ids=["other sources", "another Python", "another numba", "no CPU recorded"],
)
def test_a_store_written_for_other_sources_python_or_numba_is_not_read(
    tmp_path, monkeypatch, stale
):
    fits = {
        "fingerprint": kernelstore.fingerprint(),
        "python": kernelstore.python_tag(),
        "numba": version("numba"),
        "magic": ["x86_64-unknown-linux-gnu", "generic", ""],
        "kernels": 1,
    }
    monkeypatch.setattr(kernelstore, "STORE", str(tmp_path))
    monkeypatch.delenv(kernelstore.SWITCH, raising=False)
    monkeypatch.delenv(kernelstore.BUILDING, raising=False)
    kernelstore.manifest.cache_clear()
    try:
        assert not kernelstore.available()  # no manifest at all
        (tmp_path / kernelstore.MANIFEST).write_text(json.dumps(fits))
        kernelstore.manifest.cache_clear()
        assert kernelstore.available()
        (tmp_path / kernelstore.MANIFEST).write_text(json.dumps(fits | stale))
        kernelstore.manifest.cache_clear()
        assert kernelstore.manifest() is None and not kernelstore.available()
    finally:
        kernelstore.manifest.cache_clear()


def test_the_sources_digest_is_the_same_in_a_clone_and_an_install_and_changes_with_any_source(
    tmp_path,
):
    ignore = shutil.ignore_patterns("__pycache__", "compiled-kernels")
    clone, install = tmp_path / "clone", tmp_path / "site-packages" / "collide2d"
    for parent in (clone, install):
        for package in kernelstore.PACKAGES:
            shutil.copytree(ROOT / package, parent / package, ignore=ignore)
    assert kernelstore.sources_digest(str(clone)) == kernelstore.sources_digest(str(install))
    assert kernelstore.sources_digest(str(clone)) == kernelstore.fingerprint()
    before = kernelstore.sources_digest(str(install))
    lanes = install / "runner" / "lanes.py"
    lanes.write_text(lanes.read_text() + "\n# edited\n")
    assert kernelstore.sources_digest(str(install)) != before


def test_the_store_says_which_kernels_it_holds_from_its_file_names_without_loading_numba(
    tmp_path, monkeypatch
):
    folder = tmp_path / "collide2d.engine.broadphase"
    folder.mkdir()
    tag = kernelstore.python_tag()
    (folder / f"broadphase._find.locals.cells-120.{tag}.nbi").write_bytes(b"")
    (folder / f"broadphase.sweep_candidates-300.{tag}.nbi").write_bytes(b"")
    (folder / "broadphase.cell_grid-40.py27.nbi").write_bytes(b"")  # another Python's
    fits = {
        "fingerprint": kernelstore.fingerprint(),
        "python": tag,
        "numba": version("numba"),
        "magic": ["x86_64-unknown-linux-gnu", "generic", ""],
    }
    (tmp_path / kernelstore.MANIFEST).write_text(json.dumps(fits))
    monkeypatch.setattr(kernelstore, "STORE", str(tmp_path))
    monkeypatch.delenv(kernelstore.SWITCH, raising=False)
    kernelstore.manifest.cache_clear()
    kernelstore._listing.cache_clear()
    try:
        assert kernelstore.holds("collide2d.engine.broadphase._find.<locals>.cells")
        assert kernelstore.holds("collide2d.engine.broadphase.sweep_candidates")
        assert not kernelstore.holds("collide2d.engine.broadphase.cell_grid")
        assert not kernelstore.holds("collide2d.engine.contact.sweep_candidates")
        monkeypatch.setenv(kernelstore.SWITCH, "off")
        assert not kernelstore.holds("collide2d.engine.broadphase.sweep_candidates")
    finally:
        kernelstore.manifest.cache_clear()
        kernelstore._listing.cache_clear()


def test_numbas_version_is_read_without_importing_it():
    assert kernelstore.numba_version() == version("numba")
