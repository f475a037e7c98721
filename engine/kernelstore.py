"""The compiled kernels a wheel ships, loaded where numba would otherwise compile them.

A kernel's first compilation costs seconds (a model's kernels together: tens of seconds, minutes on
a busy machine), where pymunk or Box2D start at once. So a release compiles the kernels once,
before the wheel is built (`python -m collide2d.runner.prebuild`), into the package's folder
`engine/compiled-kernels/`, and every install loads them from there: a first run goes compiled
at once, with nothing to compile for the scenes the store covers (docs/explanation/kernels.md,
"Kernels in the wheel").

What makes the store travel, where numba's own cache stays on the machine that wrote it:

- the code is compiled for a generic CPU of the machine's architecture (numba's NUMBA_CPU_NAME
  `generic`), and looked up under that CPU on every machine: numba's cache keys a kernel by the
  host's CPU name and features, which no two machines need share;
- a kernel's freshness is a digest of the engine's and the runner's sources (`fingerprint`), the
  same in a clone and in an install, where numba's own stamp is the source file's time;
- the store says which numba and Python wrote it (`manifest.json`); under any other it is not
  read at all, and every kernel compiles as it would without it.

A kernel the store lacks (a specialisation no prebuilt scene took) compiles as before, into
numba's own cache (`engine/jit.py`), which is read first: a kernel compiled for this very CPU
once is the faster one. Nothing here writes to the store except the prebuild, which sets
BUILDING in its environment. numba is imported only by `store_cache` (called by engine.jit).
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import sys

STORE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "compiled-kernels")
MANIFEST = "manifest.json"
# Set in the environment of the process that compiles the store (with NUMBA_CPU_NAME=generic).
BUILDING = "COLLIDE2D_KERNEL_STORE_BUILD"
# `COLLIDE2D_KERNEL_STORE=off` in the environment: the store is not read (every kernel compiles
# into numba's own cache, as without a store).
SWITCH = "COLLIDE2D_KERNEL_STORE"
# The packages whose sources make the kernels: the engine, and the runner beside it.
PACKAGES = ("engine", "runner")


def building() -> bool:
    """Whether this process compiles into the store (the prebuild's)."""
    return os.environ.get(BUILDING, "") not in ("", "0")


@functools.cache
def fingerprint() -> str:
    """A digest of every Python source of the engine and the runner, by their paths inside the
    package: the same in a clone and in an installed wheel."""
    return sources_digest(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def sources_digest(parent: str) -> str:
    """The digest of the Python sources of PACKAGES in the folder `parent` (the one holding the
    engine), each by its path from `parent` and its bytes."""
    digest = hashlib.sha256()
    for package in PACKAGES:
        hash_sources(digest, os.path.join(parent, package), parent)
    return digest.hexdigest()


def hash_sources(digest, root: str, base: str) -> None:
    """Add every Python source under `root` to `digest` (a hashlib object): its path from `base`
    and its bytes (its size and time where this process may not read it)."""
    for folder, dirs, files in sorted(os.walk(root)):
        dirs.sort()
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                digest.update(os.path.relpath(path, base).replace(os.sep, "/").encode())
                try:
                    with open(path, "rb") as f:
                        digest.update(hashlib.sha256(f.read()).digest())
                except OSError:
                    stat = os.stat(path)
                    digest.update(f"{stat.st_size}:{stat.st_mtime_ns}".encode())


def python_tag() -> str:
    """The Python the store's files are for (numba's cache files name it too)."""
    return f"py{sys.version_info[0]}{sys.version_info[1]}{getattr(sys, 'abiflags', '')}"


@functools.cache
def manifest() -> dict | None:
    """The store's manifest when the store fits this install (the same sources, Python and numba
    version), else None. Reads no more than the manifest and the sources; loads no numba."""
    try:
        with open(os.path.join(STORE, MANIFEST), encoding="utf-8") as f:
            found = json.load(f)
    except (OSError, ValueError):
        return None
    fits = (
        isinstance(found, dict)
        and found.get("fingerprint") == fingerprint()
        and found.get("python") == python_tag()
        and found.get("numba") == numba_version()
        and isinstance(found.get("magic"), list)
    )
    return found if fits else None


def numba_version() -> str | None:
    """The installed numba's version, from its distribution's `.dist-info` folder name (as
    installers name it), without importing numba or importlib.metadata (a run that stays
    interpreted loads neither); None when numba or that folder is not found."""
    import importlib.util

    spec = importlib.util.find_spec("numba")
    if spec is None or not spec.origin:
        return None
    site = os.path.dirname(os.path.dirname(spec.origin))
    try:
        names = os.listdir(site)
    except OSError:
        return None
    for name in sorted(names):
        if name.startswith("numba-") and name.endswith(".dist-info"):
            return name[len("numba-") : -len(".dist-info")]
    return None


def available() -> bool:
    """Whether the store holds kernels this install can load (and may: see SWITCH)."""
    if os.environ.get(SWITCH, "").strip().lower() in ("0", "off", "no", "false"):
        return False
    return manifest() is not None and not building()


def holds(name: str) -> bool:
    """Whether the store has code of the kernel named `module.qualname` (of some
    specialisation), from its file names: loads nothing."""
    return available() and name.replace("<", "").replace(">", "") in _listing()


def holds_model(model: str) -> bool:
    """Whether the store has kernels of the built-in model `model` (the prebuild ran its scenes)."""
    prefix = f"collide2d.engine.models.{model}."
    return available() and any(name.startswith(prefix) for name in _listing())


@functools.cache
def _listing() -> frozenset:
    """`module.qualname` of every kernel in the store (without `<` and `>`, as numba names its
    files), from its index files' names (`STEM.QUALNAME-LINE.PYTHON.nbi` in the module's folder)."""
    found = set()
    suffix = f".{python_tag()}.nbi"
    for module in os.listdir(STORE):
        folder = os.path.join(STORE, module)
        if not os.path.isdir(folder):
            continue
        stem = module.rsplit(".", 1)[-1] + "."
        for name in os.listdir(folder):
            if name.endswith(suffix) and name.startswith(stem):
                qualname = name[len(stem) : -len(suffix)].rsplit("-", 1)[0]
                found.add(f"{module}.{qualname}")
    return frozenset(found)


def write_manifest(magic: tuple, kernels: int) -> str:
    """After a prebuild: the manifest that makes the store readable (returns its path)."""
    import numba

    path = os.path.join(STORE, MANIFEST)
    found = {
        "fingerprint": fingerprint(),
        "python": python_tag(),
        "numba": numba.__version__,
        "magic": list(magic),
        "kernels": kernels,
    }
    with open(path, "w", encoding="utf-8") as f:
        json.dump(found, f, indent=1)
        f.write("\n")
    manifest.cache_clear()
    _listing.cache_clear()
    return path


def store_cache(base_impl):
    """The cache class of the store, from numba's cache implementation `base_impl` (engine.jit's,
    which keeps parallel kernels' reload hooks): kernels are found by module, stamped by
    `fingerprint()` and keyed under the generic CPU the prebuild compiled for."""
    from numba.core.caching import FunctionCache, _CacheLocator

    class StoreLocator(_CacheLocator):
        def __init__(self, py_func):
            self._path = os.path.join(STORE, py_func.__module__)
            self._lineno = py_func.__code__.co_firstlineno

        def ensure_cache_path(self):
            if not building():
                raise OSError("the kernel store is written by the prebuild only")
            os.makedirs(self._path, exist_ok=True)

        def get_cache_path(self):
            return self._path

        def get_source_stamp(self):
            return fingerprint()

        def get_disambiguator(self):
            return str(self._lineno)

        @classmethod
        def from_function(cls, py_func, py_file):
            return cls(py_func)

    impl = type("StoreCacheImpl", (base_impl,), {"_locator_classes": [StoreLocator]})

    def index_key(self, sig, codegen):
        key = FunctionCache._index_key(self, sig, codegen)
        if building():
            return key
        return (key[0], tuple(manifest()["magic"]), *key[2:])

    return type("StoreCache", (FunctionCache,), {"_impl_class": impl, "_index_key": index_key})


class Stacked:
    """numba's own cache of a kernel (read first, written by every compilation) over the store's
    (read only): the `_cache` of a kernel's dispatcher when the store is available."""

    def __init__(self, own, store):
        self.own, self.store = own, store

    @property
    def cache_path(self):
        return self.own.cache_path

    def load_overload(self, sig, target_context):
        found = self.own.load_overload(sig, target_context)
        return found if found is not None else self.store.load_overload(sig, target_context)

    def save_overload(self, sig, data):
        self.own.save_overload(sig, data)

    def enable(self):
        self.own.enable()
        self.store.enable()

    def disable(self):
        self.own.disable()
        self.store.disable()

    def flush(self):
        self.own.flush()

    def holds_any(self) -> bool:
        """Whether either cache has code of the kernel, fresh for these sources."""
        return any(cache._cache_file._load_index() for cache in (self.own, self.store))
