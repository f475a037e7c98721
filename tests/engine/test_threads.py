"""Stages split among threads give the same bytes as one thread: the stepped model's move and
narrow phase, the paper model's move, broad and narrow stages, the rasteriser's full redraw, and
a whole run through the command line."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.engine import threads
from collide2d.engine.models import make
from collide2d.engine.models.stepped import model as stepped_model
from collide2d.engine.picture import raster
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_POLYGON, Bodies, Looks, WorldSpec
from collide2d.runner.command.main import main


def dense_boxes(n, seed, world):
    """n boxes of mixed sizes, packed so that many overlap after a step (many near pairs)."""
    rng = np.random.default_rng(seed)
    size = rng.integers(3, 9, (n, 2)).astype(float)
    cols = int(world.width // 9)
    idx = rng.choice(cols * int(world.height // 9), n, replace=False)
    pos = np.stack([idx % cols * 9.0, idx // cols * 9.0], 1)
    vel = rng.uniform(-400, 400, (n, 2))
    return Bodies.boxes(pos, size, vel, mass=rng.uniform(0.5, 3, n))


def run_stepped(monkeypatch, chunks, bodies, world, geometry=None):
    monkeypatch.setattr(stepped_model, "chunks_for", lambda n: chunks)
    model = make("stepped", world, bodies, geometry=geometry)
    assert int(model._bp.state[stepped_model.ST_CHUNKS]) == chunks
    events = model.advance(40)
    return (
        events.tobytes(),
        model.positions().tobytes(),
        model.velocities().tobytes(),
        (model.event_counts()),
    )


@pytest.mark.parametrize("chunks", [2, 3])
def test_the_stepped_model_split_gives_the_bytes_of_one_thread(monkeypatch, chunks):
    world = WorldSpec(270, 180, 30)
    bodies = dense_boxes(500, 1, world)
    one = run_stepped(monkeypatch, 1, bodies, world)
    split = run_stepped(monkeypatch, chunks, bodies, world)
    assert one[3][0] > 100 and one[3][1] > 100  # walls and pairs both happened
    assert split == one


def test_a_near_list_too_small_for_a_share_grows(monkeypatch):
    # every pair lands in the last share of the candidate list: the shares overflow and the
    # stage grows its buffer and asks again, with the same answer
    world = WorldSpec(60, 60, 10)
    pos = [[x, 0.0] for x in range(0, 60, 3)]
    bodies = Bodies.boxes(pos, [4, 4], [[0, 5]] * len(pos))
    assert run_stepped(monkeypatch, 7, bodies, world) == run_stepped(monkeypatch, 1, bodies, world)


def run_paper(monkeypatch, chunks, bodies, world, broadphase=None):
    from collide2d.engine.models.paper import model as paper_model

    monkeypatch.setattr(paper_model, "chunks_for", lambda n: chunks)
    model = make("paper", world, bodies, broadphase=broadphase)
    assert model._plan.chunks == chunks
    # small first calls: the event log and the candidate list outgrow their buffers mid-run
    events = np.concatenate([model.advance(k) for k in (1, 1, 58)])
    return events.tobytes(), model._S.pos.tobytes(), model._S.step.tobytes(), model.event_counts()


@pytest.mark.parametrize("chunks", [2, 3])
@pytest.mark.parametrize("broadphase", [None, "sweep"])
def test_the_paper_model_split_gives_the_bytes_of_one_thread(monkeypatch, chunks, broadphase):
    # a crowd in a small world at 10 fps: walls and pairs every tick, the candidate list made
    # anew often (the cells finder splits its pair tests; the sweep does not)
    rng = np.random.default_rng(7)
    n = 600
    cells = rng.choice(40 * 30, size=n, replace=False)
    pos = np.stack([cells % 40 * 8, cells // 40 * 8], axis=1)
    vel = rng.integers(-60, 61, size=(n, 2))
    world = WorldSpec(320, 240, 10)
    bodies = Bodies.boxes(pos, 7, vel)
    one = run_paper(monkeypatch, 1, bodies, world, broadphase)
    split = run_paper(monkeypatch, chunks, bodies, world, broadphase)
    assert one[3][0] > 100 and one[3][1] > 500  # walls and pairs both happened
    assert split == one


def test_the_full_redraw_split_in_bands_gives_the_same_frame(monkeypatch):
    rng = np.random.default_rng(3)
    n = 300
    world = WorldSpec(157, 101, 10)
    kind = rng.choice([KIND_BOX, KIND_CIRCLE, KIND_POLYGON], n).astype(np.int8)
    poly = [[0, 0], [9, 2], [4, 11]]
    vert_start = np.concatenate([[0], np.cumsum(np.where(kind == KIND_POLYGON, 3, 0))])
    bodies = Bodies(
        kind=kind,
        pos=rng.uniform(-10, 160, (n, 2)),
        size=np.where(kind[:, None] == KIND_POLYGON, [10, 12], rng.integers(1, 25, (n, 1))),
        vel=np.zeros((n, 2)),
        mass=np.ones(n),
        static=np.zeros(n, bool),
        vert_start=vert_start.astype(np.int64),
        verts=np.array(poly * int((kind == KIND_POLYGON).sum()), np.int64).reshape(-1, 2),
        looks=Looks(color=rng.integers(1, 9, n).astype(np.uint8), fill=rng.random(n) < 0.5),
    )
    frames = []
    for bands in (1, 2, 5):
        monkeypatch.setattr(raster, "chunks_for", lambda n, b=bands: b)
        r = raster.Renderer(world, bodies)
        assert r._bands == bands
        frames.append(r.draw_full(bodies.pos).tobytes())
    assert frames[0] == frames[1] == frames[2]
    assert len(set(frames[0])) > 5  # something was drawn


def test_set_threads_checks_and_clips():
    before = threads.threads()
    try:
        assert threads.set_threads(10_000) == threads.available()
        assert threads.set_threads(1) == 1 and threads.chunks_for(10**7) == 1
        with pytest.raises(ValueError):
            threads.set_threads(0)
    finally:
        threads.set_threads(before)


def test_a_run_gives_the_same_bytes_with_any_threads(tmp_path, monkeypatch):
    monkeypatch.setattr(threads, "PARALLEL_MIN_OBJECTS", 1)
    scene = tmp_path / "s.yaml"
    scene.write_text(
        "version: 1\nname: s\nworld: {width: 200, height: 150, fps: 30}\nmodel: stepped\n"
        "ticks: 30\ngenerate:\n  - {count: 300, shape: box, size: 4, speed: {min: 50, max: 300},"
        " seed: 2}\noutput: {frames: [0, 29], gif: false, events: true}\n"
    )
    outs = []
    for t in ("1", "2"):
        out = tmp_path / t
        assert main(["run", str(scene), "--out", str(out), "--png", "--quiet", "--threads", t]) == 0
        outs.append(
            {
                str(p.relative_to(out)): p.read_bytes()
                for p in sorted(out.rglob("*"))
                if p.is_file() and p.name != "summary.json"
            }
        )
    assert outs[0] == outs[1]
    assert {"s/events.jsonl", "s/final.csv"} <= set(outs[0]) and len(outs[0]) == 4


@pytest.mark.parametrize("chunks, room", [(2, 4000), (3, 4000), (4, 40)])
def test_the_cells_broad_phase_split_gives_the_same_keys(chunks, room):
    from collide2d.engine import broadphase as bp

    rng = np.random.default_rng(chunks)
    lo = rng.uniform(0, 200, (700, 2))
    hi = lo + rng.uniform(1, 9, (700, 2))
    movable = rng.random(700) < 0.9
    ws = bp.workspace(700)
    one, split = np.empty(room, np.int64), np.empty(room, np.int64)
    order1, order2 = np.empty(700, np.int64), np.empty(700, np.int64)
    k1 = bp.cell_candidates(lo, hi, movable, 9.5, order1, one, ws)
    found, ws2 = np.zeros(chunks, np.int64), bp.workspace(700)
    k2 = bp.cell_candidates_split_into(lo, hi, movable, 9.5, order2, split, ws2, found)
    assert order1.tobytes() == order2.tobytes()
    if k1 <= room and k2 <= room:
        assert k1 == k2 and one[:k1].tobytes() == split[:k2].tobytes() and k1 > 100
    else:  # too small: both ask for more, and then agree
        assert k2 > room
        big = np.empty(2 * max(k1, k2), np.int64)
        k3 = bp.cell_candidates_split_into(
            lo, hi, movable, 9.5, order2, big, bp.workspace(700), found
        )
        full = np.empty(2 * max(k1, k2), np.int64)
        k4 = bp.cell_candidates(lo, hi, movable, 9.5, order1, full, ws)
        assert k3 == k4 and big[:k3].tobytes() == full[:k4].tobytes()
