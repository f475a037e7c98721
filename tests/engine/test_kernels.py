"""The kernels compiled with numba's private `_nrt=False` (no reference counting) still compile.

`_nrt=False` is not part of numba's public API; the hot kernels use it because counting references
took ~85 % of the run time on event-heavy scenes. These tests find every kernel that uses it, run
each model on a tiny scene so that each is compiled, and check that each was compiled with the
option, so that a numba upgrade that drops or changes it fails here, loudly, rather than as a slow
run. Under NUMBA_DISABLE_JIT=1 there is nothing compiled to check.
"""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest
from numba.core.config import DISABLE_JIT

import collide2d.engine
from collide2d.engine import jit
from collide2d.engine.models import make
from collide2d.engine.world import Bodies, WorldSpec

pytestmark = pytest.mark.skipif(DISABLE_JIT, reason="NUMBA_DISABLE_JIT: nothing is compiled")

# Every kernel compiled with _nrt=False, by module and name (a new one is added here on purpose).
EXPECTED = {
    ("collide2d.engine.models.paper.model", "_run"),
    ("collide2d.engine.models.exact.model", "_run"),
}


def _engine_modules():
    root = collide2d.engine
    yield root
    for info in pkgutil.walk_packages(root.__path__, root.__name__ + "."):
        yield importlib.import_module(info.name)


def _no_nrt_kernels() -> dict[tuple[str, str], jit.Kernel]:
    found = {}
    for module in _engine_modules():
        for name, obj in vars(module).items():
            if (
                isinstance(obj, jit.Kernel)
                and obj.py_func.__module__ == module.__name__
                and obj.targetoptions.get("_nrt") is False
            ):
                found[(module.__name__, name)] = obj
    return found


def _tiny_runs() -> None:
    """Each model over two boxes that meet and hit the walls: every kernel compiles and runs."""
    world = WorldSpec(40, 20, 10)
    bodies = Bodies.boxes([[2, 5], [24, 5]], 6, [[40, 0], [-30, 0]])
    for name in ("paper", "stepped", "exact"):
        model = make(name, world, bodies)
        events = model.advance(10)
        assert len(events) > 0
        assert np.isfinite(model.positions()).all()


def test_the_kernels_without_reference_counting_are_the_expected_ones():
    assert set(_no_nrt_kernels()) == EXPECTED


def test_every_kernel_without_reference_counting_compiles():
    with jit.lane(True):
        _tiny_runs()
    for where, kernel in _no_nrt_kernels().items():
        assert kernel.signatures, f"{where} was not compiled by a model run"
        for signature in kernel.signatures:
            # compiled (or loaded from the cache) with the option still in force
            assert kernel.overloads[signature].entry_point is not None, where
        assert kernel.targetoptions["_nrt"] is False, where
