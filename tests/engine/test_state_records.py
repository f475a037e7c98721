"""Each model's kernel state is read by name: its records are named tuples whose fields the
kernels read, the paper model's whole-number settings and the exact model's grid sizes are whole
numbers (not slots of a float array), no kernel of a model takes more than MAX_PARAMETERS
parameters, and no kernel of the paper or exact model unpacks a record it is handed by position.

The kernels are read from the sources, so the source tests load no kernel.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from collide2d.engine import jit
from collide2d.engine.models import make
from collide2d.engine.models.exact.state import named, plain
from collide2d.engine.world import Bodies, WorldSpec

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "engine" / "models"
MAX_PARAMETERS = 10
# The models whose kernels keep to MAX_PARAMETERS (and, for a model only partly so far, the
# modules whose kernels do).
BOUNDED = {"paper": None, "exact": None, "stepped": ("candidates.py", "narrow.py")}
# The models whose kernels never unpack a record they are handed by position.
BY_NAME = ("paper", "exact")


def is_named_record(value) -> bool:
    return isinstance(value, tuple) and hasattr(type(value), "_fields")


def _trees(folder: Path):
    return [(path, ast.parse(path.read_text())) for path in sorted(folder.rglob("*.py"))]


def _kernel_nodes(folder: Path):
    """(file, function node) of every function of `folder` compiled by numba: decorated with njit
    or with a name made from it in any module of the folder (e.g. `hot = njit(...)`, imported)."""
    trees = _trees(folder)
    made = {  # module-level names bound to njit(...), e.g. `_kernel = njit(...)`
        t.id
        for _, tree in trees
        for node in tree.body
        if isinstance(node, ast.Assign) and "njit" in ast.unparse(node.value)
        for t in node.targets
        if isinstance(t, ast.Name)
    }
    for path, tree in trees:
        for node in ast.walk(tree):
            if not isinstance(node, ast.FunctionDef):
                continue
            decorators = [ast.unparse(d) for d in node.decorator_list]
            if any("njit" in d or d.split("(")[0] in made for d in decorators):
                yield path, node


def kernels(folder: Path):
    """(file, name, parameters) of every kernel of `folder`."""
    for path, node in _kernel_nodes(folder):
        a = node.args
        count = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)
        yield path.relative_to(ROOT), node.name, count


def unpacked_parameters(folder: Path):
    """(file, kernel, statement) of every statement of a kernel of `folder` that unpacks one of
    its parameters by position (`a, b, c = record`)."""
    for path, node in _kernel_nodes(folder):
        params = {a.arg for a in (*node.args.posonlyargs, *node.args.args)}
        for stmt in ast.walk(node):
            if (
                isinstance(stmt, ast.Assign)
                and any(isinstance(t, (ast.Tuple, ast.List)) for t in stmt.targets)
                and isinstance(stmt.value, ast.Name)
                and stmt.value.id in params
            ):
                yield str(path.relative_to(ROOT)), node.name, ast.unparse(stmt)


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
    modules = BOUNDED[model]
    found = [k for k in kernels(MODELS / model) if modules is None or k[0].name in modules]
    assert len(found) >= 5  # the reader finds the kernels
    over = [(str(f), name, n) for f, name, n in found if n > MAX_PARAMETERS]
    assert over == []


def test_the_kernel_reader_counts_parameters():
    found = {name: n for _, name, n in kernels(MODELS / "paper")}
    assert found["_window"] == 4 and found["_reach"] == 6
    assert np.all(np.array([*found.values()]) > 0)
    # kernels decorated with a name made from njit in another module (the exact model's `hot`)
    found = {name: n for _, name, n in kernels(MODELS / "exact")}
    assert found["push"] == 5 and found["move_to"] == 5 and found["_run"] == 9


def test_the_exact_model_keeps_its_state_in_named_records():
    world = WorldSpec(100, 80, 10)
    bodies = Bodies.boxes([[0, 0], [30, 0], [0, 30]], 9, [[10, 0], [-10, 5], [0, 0]])
    m = make("exact", world, bodies)
    S = m._state()
    for record in (S, S.C, S.Q, S.world):
        assert is_named_record(record)
    # the grid's sizes are whole numbers, the sides and the bucket rate floats
    assert type(S.world.gnx) is int and type(S.world.gny) is int
    assert (S.world.width, S.world.height, S.world.fps) == (100.0, 80.0, 10.0)
    assert S.Q.state.dtype == np.int64 and type(S.Q.rate) is float
    assert S.st.dtype == np.int64 and S.N.dtype == np.int64 and S.F.dtype == np.float64
    # the kernel is handed plain tuples (numba types those fast) and names them again
    flat = plain(S)
    assert type(flat) is tuple and not any(is_named_record(x) for x in flat)
    with jit.lane(False):
        again = named(flat)
    assert again == S and all(is_named_record(r) for r in (again.C, again.Q, again.world))
    m.advance(12)
    # 0 and 1, 21 px apart closing at 20 px/s, meet at 1.05 s (1 is 5.25 px lower: they overlap
    # on y) and swap their x velocities; no object reaches a wall it moves towards by 1.2 s
    assert m.event_counts() == (0, 1)
    assert m.velocities()[:2].tolist() == [[-10.0, 0.0], [10.0, 5.0]]


@pytest.mark.parametrize("model", BY_NAME)
def test_no_kernel_unpacks_a_record_it_is_handed_by_position(model):
    assert list(unpacked_parameters(MODELS / model)) == []


def test_the_unpacking_reader_finds_positional_unpacking():
    # the stepped model still unpacks some records it is handed (scratch tuples, the world)
    found = {name for _, name, _ in unpacked_parameters(MODELS / "stepped")}
    assert "run" in found
