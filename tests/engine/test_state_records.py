"""Each model's kernel state is read by name: its records are named tuples whose fields the
kernels read, the paper model's whole-number settings are whole numbers (not slots of a float
array), and no kernel of a model takes more than MAX_PARAMETERS parameters.

The kernels are read from the sources, so the last test loads no kernel.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from collide2d.engine.models import make
from collide2d.engine.world import Bodies, WorldSpec

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "engine" / "models"
MAX_PARAMETERS = 10
# The models whose kernels keep to MAX_PARAMETERS.
BOUNDED = ("paper",)


def is_named_record(value) -> bool:
    return isinstance(value, tuple) and hasattr(type(value), "_fields")


def kernels(folder: Path):
    """(file, name, parameters) of every function of `folder` compiled by numba (decorated with
    njit or a name made from it)."""
    for path in sorted(folder.rglob("*.py")):
        tree = ast.parse(path.read_text())
        made = {  # module-level names bound to njit(...), e.g. `_kernel = njit(...)`
            t.id
            for node in tree.body
            if isinstance(node, ast.Assign) and "njit" in ast.unparse(node.value)
            for t in node.targets
            if isinstance(t, ast.Name)
        }
        for node in ast.walk(tree):
            if not isinstance(node, ast.FunctionDef):
                continue
            decorators = [ast.unparse(d) for d in node.decorator_list]
            if any("njit" in d or d.split("(")[0] in made for d in decorators):
                a = node.args
                count = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)
                yield path.relative_to(ROOT), node.name, count


def paper_model():
    pos = [[0, 0], [30, 0], [0, 30]]
    return make("paper", WorldSpec(100, 80, 10), Bodies.boxes(pos, 9, [[10, 0], [-10, 5], [0, 0]]))


def test_the_paper_model_keeps_its_state_in_named_records():
    m = paper_model()
    for record in (m._S, m._plan, m._lists):
        assert is_named_record(record)
    assert m._S.pos.shape == m._S.step.shape == m._lists.disp.shape == (3, 2)
    # the settings the kernel counts with are whole numbers, not slots of a float array
    for field in ("window", "cap", "longest", "chunks"):
        assert type(getattr(m._plan, field)) is int
    m.advance(5)
    assert m._plan.chunks == 1 and m.positions()[0].tolist() == [5.0, 0.0]


def test_the_stepped_model_keeps_its_state_in_named_records():
    world = WorldSpec(100, 80, 10)
    m = make("stepped", world, Bodies.boxes([[0, 0], [30, 0]], 9, [[10, 0], [-10, 0]]))
    assert is_named_record(m._S) and is_named_record(m._bp)
    assert m._bp.state.dtype == np.int64 and m._bp.params.dtype == np.float64
    before = m._bp.order
    m.advance(12)
    assert m._bp.order is before and m.event_counts()[1] == 1  # the pair met once


@pytest.mark.parametrize("model", BOUNDED)
def test_no_kernel_of_a_model_takes_more_than_ten_parameters(model):
    found = list(kernels(MODELS / model))
    assert len(found) >= 5  # the reader finds the kernels
    over = [(str(f), name, n) for f, name, n in found if n > MAX_PARAMETERS]
    assert over == []


def test_the_kernel_reader_counts_parameters():
    found = {name: n for _, name, n in kernels(MODELS / "paper")}
    assert found["_window"] == 4 and found["_reach"] == 6
    assert np.all(np.array([*found.values()]) > 0)
