"""The stepped model (docs/models.md#stepped): analytic outcomes, invariants, walls, statics,
determinism, and the broad phase and skips changing nothing against a plain all-pairs version of the
model."""

import numpy as np
import pytest
from engine_refs import random_boxes
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.broadphase import KEY_SHIFT
from collide2d.engine.contact import box_sweep
from collide2d.engine.events import (
    AXIS_NAMES,
    EV_PAIR,
    EV_WALL,
    SIDE_LEFT,
    SIDE_RIGHT,
    new_log,
)
from collide2d.engine.invariants import kinetic_energy, momentum
from collide2d.engine.models import make
from collide2d.engine.models.stepped import model as stepped_model
from collide2d.engine.models.stepped.approach import box_clip, box_step_contact
from collide2d.engine.models.stepped.candidates import (
    BANDS,
    REORDER_ROWS,
    ST_BANDS,
    ST_FUSED,
    ST_KEYS,
    keys_within,
    within_reach,
)
from collide2d.engine.models.stepped.model import STAGES
from collide2d.engine.models.stepped.narrow import narrow
from collide2d.engine.models.stepped.records import Step
from collide2d.engine.models.stepped.step import step
from collide2d.engine.response import exchange, fold, separate
from collide2d.engine.world import KIND_CIRCLE, Bodies, Looks, WorldSpec


def boxes_overlap(pos, size):
    """Pairs whose boxes overlap with positive area."""
    lo, hi = pos, pos + size
    n = len(pos)
    return [
        (a, b)
        for a in range(n)
        for b in range(a + 1, n)
        if (lo[a] < hi[b]).all() and (lo[b] < hi[a]).all()
    ]


def inside(model, bodies, world):
    p = model.positions()
    return bool((p >= 0).all() and (p + bodies.size <= [world.width, world.height]).all())


def test_tunnelling_at_one_fps_passes_through_without_a_collision():
    world = WorldSpec(320, 240, 1)
    bodies = Bodies.boxes([[100, 115], [210, 115]], 10, [[10, 0], [-10, 0]])
    model = make("stepped", world, bodies)
    for _ in range(12):
        assert len(model.advance(1)) == 0
        assert boxes_overlap(model.positions(), bodies.size) == []
    assert model.positions().tolist() == [[220, 115], [90, 115]]
    assert model.tick == 12


def test_at_ten_fps_the_same_pair_collides_and_swaps():
    world = WorldSpec(320, 240, 10)
    bodies = Bodies.boxes([[100, 115], [210, 115]], 10, [[10, 0], [-10, 0]])
    model = make("stepped", world, bodies)
    events = model.advance(60)
    assert len(events) == 1
    e = events[0]
    assert (e["type"], e["a"], e["b"], AXIS_NAMES[e["code"]]) == (EV_PAIR, 0, 1, "x")
    assert (e["tick"], e["t"], e["xdiff"]) == (51, 5.1, -1)  # first overlap at tick 51
    assert model.velocities().tolist() == [[-10, 0], [10, 0]]


@pytest.mark.parametrize("m1,m2", [(1.0, 1.0), (9.0, 1.0), (1.0, 3.0), (2.5, 0.5)])
def test_head_on_unequal_masses_give_the_textbook_velocities(m1, m2):
    world = WorldSpec(1000, 100, 20)
    v1, v2 = 30.0, -10.0
    bodies = Bodies.boxes([[100, 45], [300, 45]], 10, [[v1, 0], [v2, 0]], mass=[m1, m2])
    model = make("stepped", world, bodies, substeps=4)
    events = model.advance(200)
    assert [(e["type"], e["a"], e["b"]) for e in events] == [(EV_PAIR, 0, 1)]
    u1 = ((m1 - m2) * v1 + 2 * m2 * v2) / (m1 + m2)
    u2 = ((m2 - m1) * v2 + 2 * m1 * v1) / (m1 + m2)
    assert model.velocities()[:, 0] == pytest.approx([u1, u2], rel=1e-14, abs=1e-13)


def test_newtons_cradle_passes_the_speed_to_the_last_box():
    world = WorldSpec(320, 60, 10)
    xs = [20] + [100 + 10 * k for k in range(5)]
    bodies = Bodies.boxes([[x, 25] for x in xs], 10, [[50, 0]] + [[0, 0]] * 5)
    model = make("stepped", world, bodies, substeps=8)
    model.advance(25)
    assert model.velocities()[:, 0].tolist() == [0, 0, 0, 0, 0, 50]


@pytest.mark.parametrize("fps,substeps", [(7, 1), (10, 3), (1, 50)])
def test_free_flight_between_walls_is_the_reflection_formula(fps, substeps):
    world = WorldSpec(97, 61, fps)
    x0, y0, vx, vy, w, h = 13.0, 40.0, 231.7, -83.3, 9.0, 5.0
    bodies = Bodies.boxes([[x0, y0]], [[w, h]], [[vx, vy]])
    model = make("stepped", world, bodies, substeps=substeps)
    walls = 0
    for k in range(1, 41):
        walls += len(model.advance(1))
        t = k / fps
        for axis, (p0, v, span) in enumerate(((x0, vx, 97 - w), (y0, vy, 61 - h))):
            y = (p0 + v * t) % (2 * span)
            expected = y if y <= span else 2 * span - y
            assert model.positions()[0, axis] == pytest.approx(expected, abs=1e-9)
    # One wall event per fold: the number of wall lines the free coordinate crossed.
    t = 40 / fps
    crossings = sum(int(abs(np.floor((p0 + v * t) / span))) for p0, v, span in
                    ((x0, vx, 97 - w), (y0, vy, 61 - h)))  # fmt: skip
    assert walls == crossings


def test_wall_events_name_the_side_and_reverse_the_component():
    world = WorldSpec(100, 100, 10)
    model = make("stepped", world, Bodies.boxes([[85, 50]], 10, [[30, 0]]))
    events = model.advance(3)
    assert [(e["type"], e["a"], e["b"], e["code"]) for e in events] == [
        (EV_WALL, 0, -1, SIDE_RIGHT)
    ]
    assert model.velocities().tolist() == [[-30, 0]]
    model = make("stepped", world, Bodies.boxes([[1, 50]], 10, [[-30, 0]]))
    assert model.advance(1)["code"].tolist() == [SIDE_LEFT]
    assert model.positions()[0, 0] == pytest.approx(2.0)


@pytest.mark.parametrize("geometry", ["box", "exact"])
def test_energy_and_momentum_are_kept_in_a_pair_only_scene(geometry):
    # A crowd in the middle of a large world: many collisions, no wall reached in the run.
    world = WorldSpec(4000, 4000, 20)
    inner = random_boxes(36, seed=3, world=WorldSpec(120, 120, 20), speed=20.0)
    bodies = Bodies.boxes(inner.pos + 1900, inner.size, inner.vel, mass=inner.mass)
    model = make("stepped", world, bodies, substeps=2, geometry=geometry)
    events = model.advance(200)
    assert (events["type"] == EV_PAIR).sum() > 20 and (events["type"] == EV_WALL).sum() == 0
    e0 = kinetic_energy(bodies.mass, bodies.static, bodies.vel)
    p0 = np.array(momentum(bodies.mass, bodies.static, bodies.vel))
    v = model.velocities()
    assert kinetic_energy(bodies.mass, bodies.static, v) == pytest.approx(e0, rel=1e-12)
    p1 = np.array(momentum(bodies.mass, bodies.static, v))
    scale = float(np.sum(bodies.mass * np.abs(bodies.vel).max(axis=1)))
    assert np.abs(p1 - p0).max() <= 1e-12 * scale


def test_energy_is_kept_with_walls_over_a_long_run():
    world = WorldSpec(200, 150, 30)
    bodies = random_boxes(40, seed=5, world=world, mass_range=(0.1, 10.0))
    model = make("stepped", world, bodies, substeps=2)
    events = model.advance(1500)
    assert (events["type"] == EV_PAIR).sum() > 200
    e0 = kinetic_energy(bodies.mass, bodies.static, bodies.vel)
    e1 = kinetic_energy(bodies.mass, bodies.static, model.velocities())
    assert e1 == pytest.approx(e0, rel=1e-12)
    assert inside(model, bodies, world)


def test_a_static_object_never_moves_and_reflects_what_hits_it():
    world = WorldSpec(200, 100, 10)
    bodies = Bodies.boxes(
        [[20, 45], [100, 0]], [[10, 10], [10, 100]], [[40, 0], [5, 5]], static=[False, True]
    )
    model = make("stepped", world, bodies, substeps=4)
    events = model.advance(30)
    assert [(e["a"], e["b"]) for e in events if e["type"] == EV_PAIR] == [(0, 1)]
    assert model.positions()[1].tolist() == [100, 0]
    assert model.velocities().tolist() == [[-40, 0], [0, 0]]


def test_extreme_mass_ratio_keeps_everything_finite_and_conserved():
    world = WorldSpec(3000, 100, 10)
    mass = [1e10, 1.0]
    bodies = Bodies.boxes([[100, 45], [400, 45]], 10, [[10, 0], [0, 0]], mass=mass)
    model = make("stepped", world, bodies, substeps=10)
    events = model.advance(400)
    v = model.velocities()
    assert np.isfinite(v).all() and np.isfinite(model.positions()).all()
    assert [(e["a"], e["b"]) for e in events] == [(0, 1)]
    # The light box leaves at twice the heavy one's speed (to 1e-10), the heavy one barely slows.
    assert v[1, 0] == pytest.approx(20.0 * 1e10 / (1e10 + 1), rel=1e-14)
    e0 = kinetic_energy(bodies.mass, bodies.static, bodies.vel)
    assert kinetic_energy(bodies.mass, bodies.static, v) == pytest.approx(e0, rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 25), st.sampled_from([1, 5, 10]))
def test_nothing_ever_leaves_the_world(seed, n, fps):
    world = WorldSpec(90, 70, fps)
    bodies = random_boxes(n, seed, world, speed=400.0)
    model = make("stepped", world, bodies, substeps=2)
    for _ in range(10):
        model.advance(3)
        assert inside(model, bodies, world)
        assert np.isfinite(model.velocities()).all()


def test_same_input_same_bytes_and_chunks_do_not_matter():
    world = WorldSpec(160, 120, 10)
    bodies = random_boxes(30, seed=9, world=world)
    a = make("stepped", world, bodies, substeps=3)
    b = make("stepped", world, bodies, substeps=3)
    ev_a = a.advance(120)
    ev_b = np.concatenate([b.advance(1) for _ in range(120)])
    assert ev_a.tobytes() == ev_b.tobytes()
    assert a.positions().tobytes() == b.positions().tobytes()
    assert a.velocities().tobytes() == b.velocities().tobytes()
    # The bodies handed in are not touched.
    assert bodies.pos.tobytes() == random_boxes(30, seed=9, world=world).pos.tobytes()


def test_log_off_gives_no_events_and_the_same_state():
    world = WorldSpec(160, 120, 10)
    bodies = random_boxes(20, seed=4, world=world)
    a, b = make("stepped", world, bodies), make("stepped", world, bodies)
    assert len(a.advance(50, log=False)) == 0
    assert len(b.advance(50)) > 0
    assert a.positions().tobytes() == b.positions().tobytes()


def circles(pos, d, vel):
    n = len(pos)
    return Bodies(
        kind=np.full(n, KIND_CIRCLE, np.int8),
        pos=np.array(pos, float),
        size=np.full((n, 2), float(d)),
        vel=np.array(vel, float),
        mass=np.ones(n),
        static=np.zeros(n, bool),
        looks=Looks(color=np.ones(n, np.uint8), fill=np.zeros(n, bool)),
        vert_start=np.zeros(n + 1, np.int64),
        verts=np.zeros((0, 2), np.int64),
    )


def test_exact_geometry_lets_circles_pass_where_their_boxes_collide():
    world = WorldSpec(200, 200, 10)
    # Discs of diameter 20 pass each other diagonally, centres 22 px apart at the closest: their
    # boxes overlap there by 4.4 px on both axes, the discs stay 2 px apart.
    side = 22.0 / np.sqrt(2.0)
    a_centre = np.array([50.0, 50.0])
    b_centre = np.array([70.0 + side + 20.0, 70.0 - side + 20.0])
    bodies = circles([a_centre - 10, b_centre - 10], 20, [[10, 10], [-10, -10]])
    as_box = make("stepped", world, bodies, geometry="box", substeps=4)
    exact = make("stepped", world, bodies, geometry="exact", substeps=4)
    assert (as_box.advance(40)["type"] == EV_PAIR).sum() >= 1
    assert (exact.advance(40)["type"] == EV_PAIR).sum() == 0


def test_exact_geometry_circles_exchange_along_the_centre_line():
    world = WorldSpec(400, 200, 100)
    # Equal discs, the target offset by 0.6 diameters: the normal is (0.8, 0.6).
    bodies = circles([[100, 100], [150, 112]], 20, [[40, 0], [0, 0]])
    model = make("stepped", world, bodies, geometry="exact", substeps=20)
    events = model.advance(200)
    assert [(e["a"], e["b"], AXIS_NAMES[e["code"]]) for e in events[:1]] == [(0, 1, "n")]
    v = model.velocities()
    # Equal masses: the struck disc takes the normal part, the striker keeps the tangential part.
    # The stepped normal is the centre line at the first overlapping step, at most v·dt = 0.02 px
    # of travel past the touch: its direction is off by ~0.02/20 rad, the velocities by < 0.1.
    n = np.array([0.8, 0.6])
    assert v[1] == pytest.approx(40 * 0.8 * n, abs=0.1)
    assert v[0] == pytest.approx(np.array([40.0, 0]) - 40 * 0.8 * n, abs=0.1)
    assert np.hypot(*v[0]) ** 2 + np.hypot(*v[1]) ** 2 == pytest.approx(1600, rel=1e-12)


def test_bad_options_are_refused():
    world = WorldSpec(10, 10, 1)
    bodies = Bodies.boxes([[0, 0]], 1, [[0, 0]])
    with pytest.raises(ValueError, match="substeps"):
        make("stepped", world, bodies, substeps=0)
    with pytest.raises(ValueError, match="geometry"):
        make("stepped", world, bodies, geometry="round")


# --- the broad phase changes nothing: the model equals testing every pair, in every way it runs


def reference(world, bodies, ticks, substeps=1):
    """The stepped model written plainly: every pair tested every step (overlapping at the step's
    end, or having cut a corner of each other within it), taken in the order their contacts
    began.
    Returns (events as (tick, type, a, b, code) tuples, positions, velocities)."""
    static = bodies.static
    pos = bodies.pos.astype(float)
    vel = np.where(static[:, None], 0.0, bodies.vel)
    size, inv = bodies.size, bodies.inv_mass
    width, height, fps = float(world.width), float(world.height), world.fps
    dt = 1.0 / (fps * substeps)
    log = []
    for tick in range(1, ticks + 1):
        for _ in range(substeps):
            for i in np.flatnonzero(~static):
                pos[i, 0] += vel[i, 0] * dt
                pos[i, 1] += vel[i, 1] * dt
            for i in np.flatnonzero(~static):
                for ax, span, sides in ((0, width, (0, 1)), (1, height, (2, 3))):
                    x, v, low, high, first_low = fold(pos[i, ax], vel[i, ax], span - size[i, ax])
                    pos[i, ax], vel[i, ax] = x, v
                    at_low = first_low
                    for _ in range(low + high):
                        log.append((tick, EV_WALL, i, -1, sides[0] if at_low else sides[1]))
                        at_low = not at_low
            span = np.array([width, height]) - size
            back = pos - vel * dt
            clear = ((back >= 0) & (back <= np.maximum(span, 0))).all(1)
            # Only a pair whose boxes swept over the step meet (with a pixel to spare for rounding)
            # can overlap now or have cut a corner within it: the rest are skipped unseen, which
            # keeps this reference quick in Python without a broad phase's cleverness.
            swept_lo = np.minimum(pos, back) - 1.0
            swept_hi = np.maximum(pos, back) + size + 1.0
            meet = (
                (swept_lo[:, None] < swept_hi[None]) & (swept_lo[None] < swept_hi[:, None])
            ).all(2)
            contacts = []
            for a in range(len(pos)):
                for b in range(a + 1, len(pos)):
                    if (static[a] and static[b]) or not meet[a, b]:
                        continue
                    q, u = pos[b] - pos[a], vel[b] - vel[a]
                    now = -size[b, 0] < q[0] < size[a, 0] and -size[b, 1] < q[1] < size[a, 1]
                    t_in = box_sweep(*(q - u * dt), *u, *size[a], *size[b])[0]
                    clip = box_clip(*q, *u, *size[a], *size[b], dt) and clear[a] and clear[b]
                    if now or clip:
                        contacts.append((t_in if -dt <= t_in < dt else -np.inf, a, b))
            for _, a, b in sorted(contacts):
                q, u = pos[b] - pos[a], vel[b] - vel[a]
                depth, depth_y, code, nx, ny = box_step_contact(*q, *u, *size[a], *size[b], dt)
                if depth <= 0.0:
                    continue
                *v, changed = exchange(*vel[a], *vel[b], inv[a], inv[b], code, nx, ny)
                if not changed:
                    continue
                vel[a], vel[b] = v[:2], v[2:]
                separate(
                    pos, size, a, b, inv[a], inv[b], code, nx, ny, depth, depth_y, width, height
                )
                log.append((tick, EV_PAIR, int(a), int(b), int(code)))
    return log, pos, vel


def logged(events):
    return [
        (int(e["tick"]), int(e["type"]), int(e["a"]), int(e["b"]), int(e["code"])) for e in events
    ]


def crowd(n, seed, world, statics=0.1, sizes=(4.0, 8.0, 14.0)):
    """n boxes of mixed sizes without overlap, some static, random velocities and masses."""
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(n)))
    pitch = np.array([world.width, world.height]) / k
    cells = np.stack([np.arange(n) % k, np.arange(n) // k], axis=1)
    size = rng.choice(sizes, (n, 2))
    pos = cells * pitch + rng.uniform(0, 1, (n, 2)) * np.maximum(pitch - size, 0)
    vel = rng.uniform(-150, 150, (n, 2))
    mass = rng.uniform(0.5, 4.0, n)
    return Bodies.boxes(pos, size, vel, mass=mass, static=rng.random(n) < statics)


@settings(max_examples=12, deadline=None)
@given(
    st.integers(0, 10_000),
    st.sampled_from([None, "sweep", "grid", "cells"]),
    st.sampled_from([1, 2]),
    st.booleans(),
)
def test_the_model_equals_testing_every_pair(seed, broadphase, substeps, skip):
    # Candidate lists, the scene's choice of method, the order inside and the skips change no
    # bit of the events, positions or velocities.
    world = WorldSpec(150, 110, 10)
    bodies = crowd(60, seed, world)
    ref_log, ref_pos, ref_vel = reference(world, bodies, 40, substeps)
    model = make("stepped", world, bodies, substeps=substeps, broadphase=broadphase, skip=skip)
    events = np.concatenate([model.advance(13), model.advance(1), model.advance(26)])
    assert logged(events) == ref_log
    assert model.positions().tobytes() == ref_pos.tobytes()
    assert model.velocities().tobytes() == ref_vel.tobytes()


@pytest.mark.parametrize("broadphase", ["sweep", "cells"])
def test_buffers_that_fill_mid_run_grow_and_change_no_bit(broadphase):
    # the candidate keys, their spare and this step's pairs in contact start far too small: a
    # run grows each where it fills (the list when it is made, the pairs in the middle of a
    # step) and ends on the same events, positions and velocities as a run that never grew
    world = WorldSpec(150, 110, 10)
    bodies = crowd(60, 3, world)
    runs = []
    for tiny in (False, True):
        model = make("stepped", world, bodies, broadphase=broadphase)
        if tiny:
            model._bp = model._bp._replace(
                keys=np.empty(1, np.int64),
                near=np.empty(1, np.int64),
                when=np.empty(1, np.float64),
                spare=np.empty(1, np.int64),
            )
        events = np.concatenate([model.advance(17), model.advance(23)])
        runs.append((events.tobytes(), model.positions().tobytes(), model.velocities().tobytes()))
        grown = (model._bp.keys.size, model._bp.near.size, model._bp.when.size)
        grown += (model._bp.spare.size,)
    assert runs[0] == runs[1]
    assert len(np.frombuffer(runs[0][0], dtype=events.dtype)) > 20
    assert min(grown) > 1  # each buffer grew


def test_a_large_crowd_through_each_method_gives_the_same_bytes():
    # 2,000 boxes in a wide world: the list is remade many times and the objects inside are put
    # back in space order; the three methods and the run in small chunks agree to the bit.
    world = WorldSpec(1600, 1200, 30)
    bodies = crowd(2000, 5, world, statics=0.05, sizes=(3.0, 6.0, 9.0))
    runs = []
    for broadphase in ("sweep", "grid", "cells"):
        model = make("stepped", world, bodies, broadphase=broadphase)
        events = model.advance(90)
        runs.append((events.tobytes(), model.positions().tobytes(), model.velocities().tobytes()))
    chunked = make("stepped", world, bodies)
    events = np.concatenate([chunked.advance(k) for k in (1, 2, 7, 30, 50)])
    runs.append((events.tobytes(), chunked.positions().tobytes(), chunked.velocities().tobytes()))
    assert all(r == runs[0] for r in runs)
    assert len(np.frombuffer(runs[0][0], dtype=events.dtype)) > 100


@pytest.mark.parametrize("broadphase", ["sweep", "cells"])
def test_the_objects_inside_follow_the_broad_phases_order(broadphase):
    # each time the list is made the objects inside are put back in the broad phase's order
    # once they strayed from it by more than REORDER_ROWS rows on average, and the listed pairs
    # renamed to match: the pair tests read the state as near-sequential streams
    world = WorldSpec(1600, 1200, 30)
    n = 2000
    bodies = crowd(n, 7, world, statics=0.05, sizes=(3.0, 6.0, 9.0))
    model = make("stepped", world, bodies, broadphase=broadphase)
    ids = []
    for ticks in (1, 5, 40, 60):
        model.advance(ticks)
        order = model._bp.order
        assert np.abs(order - np.arange(n)).sum() <= REORDER_ROWS * np.sqrt(n) * n
        keys, state = model._bp.keys, model._bp.state
        starts = state[ST_BANDS:]
        assert starts[0] == 0 and starts[-1] == state[ST_KEYS] > 500
        assert (np.diff(starts) >= 0).all()
        pairs = keys[: state[ST_KEYS]]
        assert (pairs >> KEY_SHIFT < (pairs & ((1 << KEY_SHIFT) - 1))).all()
        ids.append(model._S.ext.copy())
    assert not np.array_equal(ids[0], ids[-1])  # the order followed the objects


def test_the_bands_skipped_hold_no_pair_in_contact():
    # at every step, as the narrow phase sees the state (moved, list made), testing the whole
    # candidate list finds exactly the pairs that testing only the bands near enough to touch by
    # now finds; right after a relist only the nearest band is tested, and the share tested grows
    # with the drift
    world = WorldSpec(900, 700, 30)
    bodies = crowd(1500, 11, world, statics=0.05, sizes=(4.0, 8.0, 12.0))
    model = make("stepped", world, bodies)
    dt = 1.0 / world.fps
    rows, times = new_log(False)
    shares = []
    contacts = 0
    for tick in range(1, 61):
        for first, last in ((0, 2), (2, 4)):  # move and broad; narrow and response
            if first == 2:
                keys, state, params = model._bp.keys, model._bp.state, model._bp.params
                found = []
                for bands in (BANDS, within_reach(params)):
                    near, when = np.empty(4000, np.int64), np.empty(4000)
                    k = narrow(
                        model._S.body, model._S.ext, keys, state, bands, near, when, dt,
                        (900.0, 700.0), 1,
                    )
                    found.append(near[:k].tolist())
                assert found[0] == found[1]
                contacts += len(found[0])
                shares.append(keys_within(state, within_reach(params)) / state[ST_KEYS])
            at = Step(dt, width=900.0, height=700.0, exact=False, tick=tick, t=tick * dt, log=False)
            rows, times, _, grown = step(
                first, last, tuple(model._S), tuple(at), model._cores, rows, times, 0,
                tuple(model._bp),
            )  # fmt: skip
            model._grown(grown)
    assert contacts > 100 and min(shares) < 0.3 and max(shares) > 1.5 * min(shares)


def test_exact_shapes_keep_their_ids_whatever_the_order_inside():
    # circles by their real shape: the grid keeps objects in id order inside, the sweep and the
    # cells put them in space order; the contact tests must still see each object's own shape
    rng = np.random.default_rng(3)
    n = 150
    k = 13
    pos = np.stack([np.arange(n) % k * 24.0, np.arange(n) // k * 24.0], axis=1)
    pos += rng.uniform(0, 6, (n, 2))
    bodies = circles(pos, 14, rng.uniform(-90, 90, (n, 2)))
    world = WorldSpec(320, 300, 20)
    runs = []
    for broadphase in ("grid", "sweep", "cells"):
        model = make("stepped", world, bodies, geometry="exact", broadphase=broadphase)
        events = model.advance(60)
        runs.append((events.tobytes(), model.positions().tobytes()))
    assert runs[0] == runs[1] == runs[2]
    assert (np.frombuffer(runs[0][0], events.dtype)["type"] == EV_PAIR).sum() > 10


def test_no_pairs_between_static_objects_and_none_without_movers():
    # the skips: pairs of two static objects are never listed, and a scene without a movable
    # object has no pair stage; with skip=False all of that work is done, to the same result
    world = WorldSpec(400, 300, 30)
    rng = np.random.default_rng(8)
    n = 300
    cells = rng.choice(33 * 25, n, replace=False)
    pos = np.stack([cells % 33 * 12.0, cells // 33 * 12.0], axis=1)
    static = np.ones(n, bool)
    static[:3] = False
    bodies = Bodies.boxes(pos, 10.0, rng.uniform(-200, 200, (n, 2)), static=static)
    a, b = make("stepped", world, bodies), make("stepped", world, bodies, skip=False)
    ev_a, ev_b = a.advance(120), b.advance(120)
    assert ev_a.tobytes() == ev_b.tobytes() and (ev_a["type"] == EV_PAIR).any()
    assert a.positions().tobytes() == b.positions().tobytes()
    assert a.velocities().tobytes() == b.velocities().tobytes()
    frozen = Bodies.boxes(pos, 10.0, 0.0, static=np.ones(n, bool))
    assert len(make("stepped", world, frozen).advance(10)) == 0


@pytest.mark.parametrize("blocks, chunks", [(1, 1), (5, 1), (5, 3), (60, 2)])
def test_blocks_of_rows_change_nothing(monkeypatch, blocks, chunks):
    # the objects inside in blocks of rows, each block's own pairs tested right behind its move
    # and the pairs between blocks after (with one object per block, every pair is between
    # blocks), on one thread and split: the events, positions and velocities of testing every
    # pair, and most steps ran the move and the narrow phase together
    monkeypatch.setattr(stepped_model, "blocks_for", lambda n: blocks)
    monkeypatch.setattr(stepped_model, "chunks_for", lambda n: chunks)
    world = WorldSpec(150, 110, 60)
    bodies = crowd(60, 3, world, statics=0.05)
    ref_log, ref_pos, ref_vel = reference(world, bodies, 60)
    model = make("stepped", world, bodies)
    events = np.concatenate([model.advance(1), model.advance(59)])
    assert sum(1 for e in ref_log if e[1] == EV_PAIR) > 10
    assert logged(events) == ref_log
    assert model.positions().tobytes() == ref_pos.tobytes()
    assert model.velocities().tobytes() == ref_vel.tobytes()
    state = model._bp.state
    assert len(state) == ST_BANDS + 2 * blocks * BANDS + 1
    assert state[ST_FUSED] > 30


def test_profile_runs_the_same_ticks_as_advance():
    world = WorldSpec(300, 200, 20)
    bodies = crowd(200, 2, world)
    a, b = make("stepped", world, bodies, substeps=2), make("stepped", world, bodies, substeps=2)
    a.advance(40, log=False)
    spent = b.profile(40)
    # each stage of the one stage list, by name, in the order the step runs them
    assert tuple(spent) == STAGES == ("move", "broad", "narrow", "response")
    assert all(v >= 0.0 for v in spent.values()) and b.tick == 40
    assert a.positions().tobytes() == b.positions().tobytes()
    assert a.velocities().tobytes() == b.velocities().tobytes()
    assert a.event_counts() == b.event_counts() and min(a.event_counts()) > 0
    # advance ran move and narrow together on most steps, profile always apart
    assert a._bp.state[ST_FUSED] > 20 and b._bp.state[ST_FUSED] == 0
    assert a.advance(20).tobytes() == b.advance(20).tobytes()


# --- the normal sees the motion: no tunnelling below one box size per step
# (docs/models.md#stepped-pairs)


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(st.integers(2, 20), st.integers(2, 20)),
    st.tuples(st.integers(2, 20), st.integers(2, 20)),
    st.floats(0.0, 1.0, exclude_max=True),  # where B's side lies along A's (0: flush, glancing)
    st.floats(0.01, 0.999),  # relative displacement per step, in the smaller box's size
    st.floats(0.0, 1.0),  # how the closing speed is shared between the two
    st.floats(-30.0, 30.0),  # a common sideways speed: the pair glides together
    st.sampled_from([1, 5, 60]),
    st.booleans(),  # along y instead of x
    st.floats(0.1, 10.0),
)
def test_no_tunnelling_below_one_box_size_per_step(sa, sb, offset, frac, share, drift, fps, on_y,
                                                   mass_b):  # fmt: skip
    # B comes at A along one axis, its other axis overlapping A's anywhere from a sliver (a
    # glancing contact) to full; the relative displacement per step is below the smaller box's
    # size. They must collide and B must never end a tick past A's near face.
    side = min(*sa, *sb)
    speed = frac * side * fps  # closing speed, px/s
    (wa, ha), (wb, hb) = sa, sb
    # along x: B left of A with a gap, y offset so that the y intervals overlap by > 0
    lateral = -hb + (ha + hb) * (0.5 * offset + 0.25) if offset else -hb + 0.01
    gap = 2.5 * speed / fps  # they meet in the third step
    pa = np.array([200.0, 200.0])
    pb = np.array([200.0 - wb - gap, 200.0 + lateral])
    va = np.array([-speed * (1 - share), drift])
    vb = np.array([speed * share, drift])
    size = np.array([[wa, ha], [wb, hb]], float)
    if on_y:
        pa, pb, va, vb, size = pa[::-1], pb[::-1], va[::-1], vb[::-1], size[:, ::-1]
    world = WorldSpec(400, 400, fps)
    bodies = Bodies.boxes([pa, pb], size, [va, vb], mass=[1.0, mass_b])
    model = make("stepped", world, bodies)
    axis = 1 if on_y else 0
    pairs = 0
    for _ in range(8):
        pairs += int((model.advance(1)["type"] == EV_PAIR).sum())
        p = model.positions()
        assert p[1, axis] + size[1, axis] <= p[0, axis] + 1e-9  # B never past A's near face
    assert pairs >= 1
