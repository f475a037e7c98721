"""What it would cost to run a set of kernels compiled: seconds to start numba, to load the cached
kernels and to compile the others, from a measured table.

The table (runner/data/compile_seconds.json, written by `python benchmarks/compile_time.py
--table`) holds, for each kernel of collide2d (`module.qualname`), the CPU seconds numba took to
compile one specialisation of it from an empty cache: its own, the kernels it calls being their
own rows, and numba's own helpers it compiles counted in it. It also holds `python_s`, the
seconds `calibration()` took on the machine of the measurement (the fastest of a few: the speed
of one core, whatever the load). Compiling is Python work as much as interpreting is: on a
machine twice as slow it takes twice the CPU time, and on a machine so busy that this process
gets half a core, twice the wall time. So `seconds` scales the table by `speed_factor()`
(`calibration()` now over `python_s`) and divides it by the share of a core the caller measured
(runner.lanes: the CPU time over the wall time of the run's ticks so far).

`seconds(kernels)` is the estimate for the kernels a run calls: NUMBA_START_S when numba is not
loaded yet, then per kernel nothing when this process has it already, CACHED_LOAD_S when numba's
cache on disk holds it (engine.jit.readiness) or the kernels the wheel ships do (engine.jit.stored,
which loads nothing), else its table seconds (UNKNOWN_KERNEL_S for one
the table lacks: a plugin's). Looking at numba's cache loads numba, unless the cache is surely
empty (engine.jit.cache_empty: a cold CI job's): a caller that may do without (runner.lanes) asks
`lower_bound` first, which loads nothing.
"""

from __future__ import annotations

import functools
import json
import time
from importlib import resources

from collide2d.engine import jit, kernelstore

# Seconds to import numba and start its threading layer, measured on this project's 2-core
# machine at a load of about 2 (0.4-0.6 s).
NUMBA_START_S = 0.5
# Seconds to load one kernel numba's cache holds (the exact model's 60 kernels load in about
# 0.5 s).
CACHED_LOAD_S = 0.01
# Seconds for one specialisation of a kernel the table lacks (about the table's median).
UNKNOWN_KERNEL_S = 0.3
# Seconds between two calibrations (a run's lane asks at each chunk boundary).
CALIBRATION_EVERY_S = 5.0

TABLE = "compile_seconds.json"
_calibrated = {"at": -1e9, "factor": 1.0}


@functools.cache
def table() -> dict:
    """The measured table: {"python_s": float, "numba": version, "kernels": {name: seconds}}."""
    text = resources.files("collide2d.runner.data").joinpath(TABLE).read_text(encoding="utf-8")
    return json.loads(text)


def calibration() -> float:
    """Seconds of a fixed piece of Python work (dict, string and list handling, as a compiler's);
    about 10 ms on this project's machine."""
    began = time.perf_counter()
    names: dict[str, list[int]] = {}
    for i in range(6_000):
        key = f"v{i % 97}.{i % 13}"
        names.setdefault(key, []).append(i)
        if len(names[key]) > 8:
            names[key] = sorted(names[key][::2], reverse=True)
    return time.perf_counter() - began


def speed_factor() -> float:
    """How much slower than at the table's measurement one core runs Python now (1: as fast),
    measured at most every CALIBRATION_EVERY_S (the shortest of three timings)."""
    now = time.perf_counter()
    if now - _calibrated["at"] > CALIBRATION_EVERY_S:
        took = min(calibration() for _ in range(3))
        _calibrated["factor"] = max(took / table()["python_s"], 0.25)
        _calibrated["at"] = time.perf_counter()
    return _calibrated["factor"]


def name(kernel) -> str:
    """A kernel's row name in the table: module.qualname."""
    return f"{kernel.py_func.__module__}.{kernel.py_func.__qualname__}"


def cold_seconds(kernel) -> float:
    """The table's seconds for one specialisation of `kernel`, unscaled."""
    return table()["kernels"].get(name(kernel), UNKNOWN_KERNEL_S)


def lower_bound(kernels, share: float = 1.0) -> float:
    """The least `seconds(kernels, share)` can be (numba's start, when it has not started: the
    kernels may all be compiled in this process already); loads nothing."""
    return start_seconds(share)


def start_seconds(share: float = 1.0) -> float:
    """Wall seconds to start numba getting `share` of a core: NUMBA_START_S / share, or nothing
    once it is loaded."""
    return 0.0 if jit.loaded() else NUMBA_START_S / share


def parts(kernel, cache_empty: bool = False) -> tuple[float, float]:
    """(seconds to load, table seconds to compile) of getting `kernel` ready to run compiled: the
    second is to be scaled by `speed_factor()`. `cache_empty` (engine.jit.cache_empty): numba's
    cache is not looked at, which would load numba."""
    if cache_empty:
        return (CACHED_LOAD_S, 0.0) if jit.stored(kernel) else (0.0, cold_seconds(kernel))
    ready = jit.readiness(kernel)
    if ready == "compiled":
        return 0.0, 0.0
    return (CACHED_LOAD_S, 0.0) if ready == "cached" else (0.0, cold_seconds(kernel))


def seconds(kernels, share: float = 1.0) -> float:
    """Wall seconds to run `kernels` compiled from now, getting `share` of a core: numba's start,
    cached loads, compilations (loads numba to look at its cache, unless it surely holds
    nothing)."""
    empty = not jit.loaded() and jit.cache_empty()
    total = start_seconds(share)
    load = cold = 0.0
    for kernel in kernels:
        loading, compiling = parts(kernel, empty)
        load, cold = load + loading, cold + compiling
    return total + (load + (cold * speed_factor() if cold else 0.0)) / share


# The kernels a model's run calls, by the prefixes of their names (for `model_seconds`, before a
# run has called any): its own package's, and the engine's shared modules it uses.
MODEL_KERNELS = {
    "exact": ("collide2d.engine.models.exact.", "collide2d.engine.contact.",
              "collide2d.engine.events.", "collide2d.engine.shapes."),
    # loading a scenario: generate blocks, the start-overlap and room checks, shapes
    "load": ("collide2d.runner.scenario.", "collide2d.engine.shapes.",
             "collide2d.engine.broadphase.", "collide2d.engine.noroom."),
}  # fmt: skip


# The engine's modules shared by the models (a model's burst of compiling takes those it calls).
SHARED_KERNELS = ("collide2d.engine.contact.", "collide2d.engine.events.",
                  "collide2d.engine.shapes.", "collide2d.engine.broadphase.",
                  "collide2d.engine.sort.", "collide2d.engine.response.",
                  "collide2d.engine.motion.", "collide2d.engine.noroom.")  # fmt: skip
MODELS = "collide2d.engine.models."
PICTURE = "collide2d.engine.picture."


def burst(kernel: str) -> tuple[str, float]:
    """(what compiles, table CPU seconds to compile it from an empty cache) when `kernel`
    (module.qualname) starts a burst of compiling: its model's kernels and the shared ones, the
    drawing kernels or the loading ones, leaving out those the wheel ships; ("kernels", 0.0) for a
    kernel the table does not know (a plugin's, or another process's: "")."""
    if kernel.startswith(MODELS):
        model = kernel[len(MODELS):].split(".")[0]
        what, prefixes = f"the {model} model's kernels", MODEL_KERNELS.get(
            model, (f"{MODELS}{model}.", *SHARED_KERNELS))
    elif kernel.startswith(PICTURE):
        what, prefixes = "the drawing kernels", (PICTURE,)
    elif kernel.startswith(MODEL_KERNELS["load"]):
        what, prefixes = "the scenario-loading kernels", MODEL_KERNELS["load"]
    else:
        return "kernels", 0.0
    kernels = table()["kernels"]
    held = kernelstore.holds
    return what, sum(s for n, s in kernels.items() if n.startswith(prefixes) and not held(n))


def model_seconds(model: str) -> float:
    """CPU seconds to start numba and compile the kernels of `model`'s runs ("load": of loading a
    scenario) from an empty cache, on the table's machine (the table's kernels under
    MODEL_KERNELS' prefixes), for a comparison with interpreting measured on that machine too (a
    slower or busier machine slows both alike)."""
    prefixes = MODEL_KERNELS[model]
    kernels = table()["kernels"]
    return NUMBA_START_S + sum(
        CACHED_LOAD_S if kernelstore.holds(name) else s
        for name, s in kernels.items()
        if name.startswith(prefixes)
    )
