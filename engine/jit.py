"""Compiled or interpreted: the one place where the engine's kernels meet numba.

Every kernel is written once, as plain Python over arrays, and decorated with `njit` from this
module (not numba's). A call runs it in one of two lanes:

- compiled: numba's `njit` with the same options, cached on disk. Fastest per step, but a process
  pays about half a second to import numba and load its first cached kernel, and seconds per
  kernel the first time one compiles;
- interpreted: the function itself, as plain Python; numba is never imported. Each step is a
  hundred times slower, but nothing is loaded or compiled: a small scene finishes before numba
  would have started.

Compiled kernels are cached on disk as numba caches them, but stamped fresh only while every
source of their package is as it was (`_package_cache`): numba itself checks only the kernel's own
file, though the code it keeps has the kernels it calls compiled in. Under numba's own cache lie
the kernels a wheel ships compiled (engine.kernelstore), read where numba's own cache has none.

The lane is a context variable: `compiled()` says which lane this thread runs, and
`lane(compiled)` sets it for a `with` block (the runner picks one per run and may switch it
between two chunks of ticks, `runner.lanes`). What the runner weighs comes from here too:
`recording()` collects the kernels a block calls interpreted (the kernels a run needs, not all),
`readiness(kernel)` says whether one is compiled in this process, cached on disk or cold, and
`cache_empty()` whether numba's cache surely holds none and `stored(kernel)` whether the kernels
the wheel ships hold it (engine.kernelstore), both without loading numba. The
default is compiled, unless the environment says `COLLIDE2D_JIT=0` (or numba's own
`NUMBA_DISABLE_JIT=1`). Both lanes give the same bytes: the kernels' arithmetic is int64 and
float64 in both, and the golden tests run every scenario in both lanes.

A compiled kernel releases the GIL while it runs (numba's `nogil`), whatever options it declares:
the other threads of the process run meanwhile, such as the one that ends a command within a
second of Ctrl-C when a long chunk of ticks holds the main thread (docs/command-line.md, "Progress
and Ctrl-C"). No kernel touches a Python object, so nothing else changes.

Inside a compiled kernel, a call to another kernel is numba's own call: a `Kernel` shows numba its
dispatcher's type (`_numba_type_`) and, for `inline="always"`, the `targetoptions` and `py_func`
numba's inliner reads. `overload(func)` registers a numba implementation of `func` the first time
numba is loaded (interpreted, `func` runs itself). `prange` is `range` until a kernel of a module
compiles, when the module's `prange` becomes numba's. `parallel=True` takes effect from numba
PARALLEL_FROM_NUMBA on (older versions crashed loading parallel kernels that cached kernels call,
numba issue 8578); below it the same source compiles serially, with the same results.

Compiled code that holds a parallel loop calls numba's threading layer, which numba starts only
when told to: compiling such code starts it, and so does loading it from the cache, through the
"reload hooks" numba stores with each cached kernel. But numba leaves a loaded kernel's hooks off
its code, from where a kernel compiled afterwards in the same process takes its own: a kernel's
second specialisation, compiled in a process that loaded the parallel kernels it calls from the
cache (a run of a sparse scene after one of a dense scene: a new broad phase in the signature),
was cached without them, and a later process that loaded it first crashed calling address 0. So
`_package_cache` puts a loaded kernel's hooks back on its code, and `numba_module` starts the
threading layer as numba loads, before any kernel is loaded: no cache can leave it unstarted.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
from contextvars import ContextVar

from collide2d.engine import kernelstore

PARALLEL_FROM_NUMBA = (0, 68)

prange = range

_overloads: list[tuple] = []
_on_load: list = []
_numba = None


def _default_compiled() -> bool:
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return False
    return os.environ.get("COLLIDE2D_JIT", "1").strip().lower() not in ("0", "off", "no", "false")


_DEFAULT = _default_compiled()
_compiled: ContextVar[bool] = ContextVar("collide2d_compiled", default=_DEFAULT)


class Called(set):
    """The kernels called interpreted in a `recording()` block; `entries` maps each of them
    called from Python, rather than from another kernel, to the kernels called under it (itself
    included): run compiled, an entry has those compiled into its own code."""

    def __init__(self):
        super().__init__()
        self.entries: dict = {}


# While a `recording()` block is open in this thread: the kernels called interpreted in it.
_called: ContextVar[Called | None] = ContextVar("collide2d_called", default=None)
# While recording: the kernels called under the entry this thread runs in (None: in none).
_under: ContextVar[set | None] = ContextVar("collide2d_under", default=None)


def compiled() -> bool:
    """Whether kernels called from this thread now run compiled."""
    return _compiled.get()


@contextlib.contextmanager
def recording():
    """A `with` block that yields the set of kernels called interpreted inside it, a `Called`
    (it grows as they are called; a kernel called only from compiled code is not seen)."""
    called = Called()
    token = _called.set(called)
    try:
        yield called
    finally:
        _called.reset(token)


def loaded() -> bool:
    """Whether numba is loaded in this process (engine.jit loads it on the first compiled call)."""
    return _numba is not None


def cache_empty() -> bool:
    """True when numba's cache surely holds no kernel of collide2d: NUMBA_CACHE_DIR is set and
    holds no index file, or it is not set and the package's own cache folders (beside the sources,
    where numba writes while it may) hold none; False when it may hold one. Loads nothing."""
    folder = os.environ.get("NUMBA_CACHE_DIR", "")
    if folder:
        return not _has_index(folder)
    engine = os.path.dirname(os.path.abspath(__file__))
    roots = [engine, os.path.join(os.path.dirname(engine), "runner")]
    if not all(os.access(root, os.W_OK) for root in roots):
        return False  # numba writes to its user-wide folder instead: not looked at here
    return not any(_has_index(root) for root in roots)


def _has_index(folder: str) -> bool:
    """Whether a numba cache index (*.nbi) lies anywhere under `folder`."""
    for _, _, files in os.walk(folder):
        if any(name.endswith(".nbi") for name in files):
            return True
    return False


def stored(kernel: Kernel) -> bool:
    """Whether the kernels the wheel ships (engine.kernelstore) have code of `kernel`, of some
    specialisation. Loads nothing."""
    return kernelstore.holds(f"{kernel.py_func.__module__}.{kernel.py_func.__qualname__}")


def readiness(kernel: Kernel) -> str:
    """How far `kernel` is from running compiled: "compiled" (this process has compiled or loaded
    it), "cached" (numba's cache on disk has code of it, fresh for these sources) or "cold" (it
    would compile). Imports numba."""
    dispatcher = kernel.dispatcher
    if dispatcher.overloads:
        return "compiled"
    cache = getattr(dispatcher, "_cache", None)
    index = getattr(cache, "_cache_file", None)
    try:
        if isinstance(cache, kernelstore.Stacked):
            return "cached" if cache.holds_any() else "cold"
        return "cached" if index is not None and index._load_index() else "cold"
    except Exception:  # an unreadable index: numba would compile
        return "cold"


@contextlib.contextmanager
def lane(compiled: bool):
    """Run the kernels called inside the block compiled (True) or interpreted (False)."""
    token = _compiled.set(bool(compiled))
    try:
        yield
    finally:
        _compiled.reset(token)


def numba_module():
    """numba, imported on first use; registers the overloads declared so far and, where kernels
    compile parallel, starts numba's threading layer."""
    global _numba
    if _numba is None:
        import numba
        from numba.extending import overload as numba_overload

        for func, impl, options in _overloads:
            numba_overload(func, **options)(impl)
        _numba = numba
        if parallel_supported():
            # numba's threading layer before any kernel loads (module docstring): a cached kernel
            # holding parallel code that finds it missing calls address 0
            numba.get_num_threads()  # starts the layer (as set_num_threads does) and reads
        for call in _on_load:
            call()
    return _numba


def when_loaded(call) -> None:
    """Call `call()` once numba is loaded: now if it is, else right after it loads."""
    if _numba is not None:
        call()
    else:
        _on_load.append(call)


def parallel_supported() -> bool:
    """Whether `parallel=True` compiles parallel kernels with the installed numba."""
    version = numba_module().__version__.split(".")[:2]
    return tuple(int(x) for x in version) >= PARALLEL_FROM_NUMBA


class Kernel:
    """A kernel: its Python function, and numba's dispatcher for it, made on first compiled use."""

    def __init__(self, func, options: dict):
        functools.update_wrapper(self, func)
        self.py_func = func
        self.targetoptions = dict(options)
        self._dispatcher = None

    @property
    def dispatcher(self):
        """numba's dispatcher of this kernel (imports numba)."""
        if self._dispatcher is None:
            numba = numba_module()
            options = dict(self.targetoptions)
            if options.get("parallel") and not parallel_supported():
                options["parallel"] = False
            scope = self.py_func.__globals__
            if scope.get("prange") is range:
                scope["prange"] = numba.prange
            cache = options.pop("cache", False)
            options.setdefault("nogil", True)  # other threads run meanwhile (module docstring)
            dispatcher = numba.njit(**options)(self.py_func)
            if cache:
                dispatcher._cache = _kernel_cache(self.py_func)
            self._dispatcher = dispatcher
        return self._dispatcher

    @property
    def _numba_type_(self):
        return self.dispatcher._numba_type_

    def __call__(self, *args, **kwargs):
        if _compiled.get():
            return (self._dispatcher or self.dispatcher)(*args, **kwargs)
        called = _called.get()
        if called is None:
            return self.py_func(*args, **kwargs)
        called.add(self)
        under = _under.get()
        if under is not None:
            under.add(self)
            return self.py_func(*args, **kwargs)
        under = called.entries.setdefault(self, {self})
        token = _under.set(under)
        try:
            return self.py_func(*args, **kwargs)
        finally:
            _under.reset(token)

    def __getattr__(self, name: str):
        # numba's dispatcher answers the rest (signatures, overloads, inspect_types, ...)
        if name.startswith("__") or name in ("_dispatcher", "py_func", "targetoptions"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __reduce__(self):
        return _kernel_named, (self.py_func.__module__, self.py_func.__qualname__)

    def __repr__(self) -> str:
        return f"<kernel {self.py_func.__module__}.{self.py_func.__qualname__}>"


def _package_root(path: str) -> str | None:
    """The outermost package folder holding the file at `path`; None outside a package."""
    folder = os.path.dirname(os.path.abspath(path))
    if not (os.path.isfile(path) and os.path.isfile(os.path.join(folder, "__init__.py"))):
        return None
    while os.path.isfile(os.path.join(os.path.dirname(folder), "__init__.py")):
        folder = os.path.dirname(folder)
    return folder


@functools.cache
def _package_fingerprint(root: str) -> str:
    """A digest of every Python source under `root`: changes when any of them does."""
    digest = hashlib.sha256()
    kernelstore.hash_sources(digest, root, root)
    return digest.hexdigest()


def _kernel_cache(py_func):
    """The on-disk cache of a kernel: numba's own (`_package_cache`), over the kernels the wheel
    ships where it has them (engine.kernelstore); the store alone in the prebuild that writes it."""
    if kernelstore.building():
        return _store_cache()(py_func)
    own = _package_cache()(py_func)
    if kernelstore.available():
        return kernelstore.Stacked(own, _store_cache()(py_func))
    return own


@functools.cache
def _store_cache():
    return kernelstore.store_cache(_reloading_impl())


@functools.cache
def _reloading_impl():
    """numba's cache implementation, putting a loaded kernel's reload hooks back on its code.

    numba runs a loaded kernel's reload hooks (a parallel kernel's: start the threading layer)
    but leaves them off its code library, from where a caller compiled later in this process
    takes its own: that caller would be cached without them (module docstring)."""
    from numba.core.caching import FunctionCache

    base = FunctionCache._impl_class

    def rebuild(self, target_context, payload):
        result = base.rebuild(self, target_context, payload)
        hooks = getattr(result, "reload_init", None)
        kept = getattr(getattr(result, "library", None), "_reload_init", None)
        if hooks and isinstance(kept, set):
            kept.update(hooks)
        return result

    return type("ReloadingCacheImpl", (base,), {"rebuild": rebuild})


@functools.cache
def _package_cache():
    """numba's on-disk cache of a function, made stale by an edit anywhere in its package.

    numba keeps a compiled kernel until the kernel's own file changes, but the code it keeps has
    the kernels it calls compiled into it: after an edit of a callee's file alone (or an upgrade
    that leaves the caller's file as it was) the old code would load, and may crash. Here the
    freshness stamp numba checks is its own (the file's) plus a digest of every source of the
    outermost package holding the file, so any edit there compiles afresh."""
    from numba.core.caching import FunctionCache

    def package_wide(locator):
        class Locator(locator):
            @classmethod
            def from_function(cls, py_func, py_file):
                found = super().from_function(py_func, py_file)
                if found is not None:
                    found.package_root = _package_root(py_file)
                return found

            def get_source_stamp(self):
                own = super().get_source_stamp()
                root = self.package_root
                return own if root is None else (own, _package_fingerprint(root))

        Locator.__name__ = Locator.__qualname__ = locator.__name__
        return Locator

    base = _reloading_impl()
    impl = type(
        "PackageCacheImpl",
        (base,),
        {"_locator_classes": [package_wide(cls) for cls in base._locator_classes]},
    )
    return type("PackageCache", (FunctionCache,), {"_impl_class": impl})


def cache_clear_hint() -> str:
    """Where numba keeps the compiled kernels and the command that clears them, for a message
    (numba is not imported: a process that has just crashed in it may say this)."""
    folder = os.environ.get("NUMBA_CACHE_DIR", "")
    if folder:
        return f"delete its folder NUMBA_CACHE_DIR ({folder}): rm -rf {_quoted(folder)}"
    # the kernels live in the engine package and the runner package beside it
    engine = os.path.dirname(os.path.abspath(__file__))
    folders = [engine, os.path.join(os.path.dirname(engine), "runner")]
    folders = [f for f in folders if os.path.isdir(f)]
    return (
        f"delete numba's files in the __pycache__ folders under {' and '.join(folders)} (or in "
        "numba's user cache folder where those are read-only): "
        f"find {' '.join(_quoted(f) for f in folders)} -name '*.nb[ci]' -delete"
    )


def _quoted(path: str) -> str:
    import shlex

    return shlex.quote(path)


def _kernel_named(module: str, qualname: str) -> Kernel:
    import importlib

    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def njit(func=None, **options):
    """`@njit` or `@njit(cache=True, ...)`: a Kernel taking numba's njit options."""
    if func is None:
        return lambda f: Kernel(f, options)
    return Kernel(func, options)


def overload(func, **options):
    """numba's `overload(func)`, registered when numba is first loaded."""

    def register(impl):
        _overloads.append((func, impl, options))
        if _numba is not None:
            from numba.extending import overload as numba_overload

            numba_overload(func, **options)(impl)
        return impl

    return register
