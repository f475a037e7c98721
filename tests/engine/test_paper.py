"""The paper model (docs/models.md#paper): counters, walls, the flip rule, undo once, and exactness
of the broad phase against a plain all-pairs reference written straight from docs/models.md."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collide2d.engine.events import AXIS_NAMES, EV_PAIR, EV_WALL, SIDE_NAMES
from collide2d.engine.models.paper.model import STAGES, Model
from collide2d.engine.world import Bodies, WorldSpec


def model(pos, size, vel, *, fps=10, world=(320, 240), static=None):
    bodies = Bodies.boxes(pos, size, vel, static=static)
    return Model(WorldSpec(world[0], world[1], fps), bodies)


def pairs_of(events):
    return [
        (int(e["a"]), int(e["b"]), AXIS_NAMES[e["code"]], int(e["xdiff"]), int(e["ydiff"]))
        for e in events
        if e["type"] == EV_PAIR
    ]


# --- a reference written from docs/models.md#paper with Fractions and a plain all-pairs loop


def reference(pos, size, vel, fps, world, ticks, static=None):
    n = len(pos)
    static = [False] * n if static is None else list(static)
    pos = [list(map(int, p)) for p in pos]
    size = [list(map(int, s)) for s in size]
    rate = [[Fraction(repr(float(v))) / fps for v in vv] for vv in vel]
    step = [[r.numerator for r in rr] for rr in rate]
    period = [[r.denominator for r in rr] for rr in rate]
    count = [[0, 0] for _ in range(n)]
    limit = world
    log = []
    for tick in range(1, ticks + 1):
        disp = [[0, 0] for _ in range(n)]
        for i in range(n):
            for ax in range(2):
                count[i][ax] += 1
                if count[i][ax] == period[i][ax]:
                    count[i][ax] = 0
                    pos[i][ax] += step[i][ax]
                    disp[i][ax] = step[i][ax]
        undone = [[False, False] for _ in range(n)]
        for i in range(n):
            for ax in range(2):
                out_low = pos[i][ax] < 0 and disp[i][ax] < 0
                out_high = pos[i][ax] + size[i][ax] > limit[ax] and disp[i][ax] > 0
                if out_low or out_high:
                    step[i][ax] = -step[i][ax]
                    pos[i][ax] -= disp[i][ax]
                    undone[i][ax] = True
                    side = ("left", "right") if ax == 0 else ("top", "bottom")
                    log.append(("wall", tick, i, side[1 if out_high else 0]))
        for a in range(n):
            for b in range(a + 1, n):
                if static[a] and static[b]:
                    continue
                xd = min(pos[a][0] + size[a][0], pos[b][0] + size[b][0]) - max(pos[a][0], pos[b][0])
                yd = min(pos[a][1] + size[a][1], pos[b][1] + size[b][1]) - max(pos[a][1], pos[b][1])
                if xd <= 0 or yd <= 0:
                    continue
                axis = "y" if xd > yd else "x" if yd > xd else "xy"
                for i in (a, b):
                    if axis in ("x", "xy"):
                        step[i][0] = -step[i][0]
                    if axis in ("y", "xy"):
                        step[i][1] = -step[i][1]
                    for ax in range(2):
                        if not undone[i][ax]:
                            pos[i][ax] -= disp[i][ax]
                            undone[i][ax] = True
                log.append(("pair", tick, a, b, axis, xd, yd))
    return pos, step, log


def logged(events):
    out = []
    for e in events:
        if e["type"] == EV_WALL:
            out.append(("wall", int(e["tick"]), int(e["a"]), SIDE_NAMES[e["code"]]))
        else:
            out.append(
                (
                    "pair",
                    int(e["tick"]),
                    int(e["a"]),
                    int(e["b"]),
                    AXIS_NAMES[e["code"]],
                    int(e["xdiff"]),
                    int(e["ydiff"]),
                )
            )
    return out


# --- Figure 2 and the tie


@pytest.mark.parametrize(
    "pos, size, vel, axis, xdiff, ydiff",
    [
        # case 1: wide overlap from above -> vertical flip
        ([[100, 100], [104, 111]], [[20, 10], [20, 10]], [[0, 10], [0, -10]], "y", 16, 1),
        # case 2: tall overlap side by side -> horizontal flip
        ([[100, 100], [111, 104]], [[10, 10], [10, 10]], [[10, 0], [-10, 0]], "x", 1, 6),
        # case 3: corners, xdiff slightly larger -> vertical flip
        ([[100, 100], [109, 110]], [[10, 10], [10, 10]], [[10, 10], [-10, -10]], "y", 3, 2),
        # case 4: the other diagonal, xdiff slightly larger -> vertical flip
        ([[100, 100], [109, 90]], [[10, 10], [10, 10]], [[10, -10], [-10, 10]], "y", 3, 2),
        # the tie, on which the paper is silent: both components flip (axis xy)
        ([[100, 100], [109, 109]], [[10, 10], [10, 10]], [[10, 10], [-10, -10]], "xy", 3, 3),
    ],
)
def test_flip_rule_on_figure_2_and_the_tie(pos, size, vel, axis, xdiff, ydiff):
    m = model(pos, size, vel)
    events = m.advance(1)
    assert pairs_of(events) == [(0, 1, axis, xdiff, ydiff)]
    flipped = np.array(vel, float)
    if axis in ("x", "xy"):
        flipped[:, 0] *= -1
    if axis in ("y", "xy"):
        flipped[:, 1] *= -1
    assert np.array_equal(m.velocities(), flipped)
    # this tick's displacement is taken back: both are where they started
    assert np.array_equal(m.positions(), np.array(pos, float))


def test_after_a_vertical_flip_the_boxes_part_vertically():
    m = model([[100, 100], [109, 110]], [[10, 10], [10, 10]], [[10, 10], [-10, -10]])
    m.advance(1)
    m.advance(3)
    (ax, ay), (bx, by) = m.positions()
    assert (ax, ay) == (103, 97) and (bx, by) == (106, 113)
    assert len(pairs_of(m.advance(5))) == 0


# --- counters (paper section II.D)


def trajectory(vx, fps, ticks):
    m = model([[100, 100]], [10, 10], [[vx, 0]], fps=fps)
    xs = []
    for _ in range(ticks):
        m.advance(1)
        xs.append(int(m.positions()[0, 0]))
    return xs


def test_5_px_per_second_at_10_fps_moves_one_pixel_every_second_tick():
    assert trajectory(5, 10, 8) == [100, 101, 101, 102, 102, 103, 103, 104]


def test_7_5_px_per_second_is_3_px_every_4_ticks():
    assert trajectory(7.5, 10, 8) == [100, 100, 100, 103, 103, 103, 103, 106]


def test_10_px_per_second_at_10_fps_moves_every_tick_and_at_1_fps_jumps_ten():
    assert trajectory(10, 10, 3) == [101, 102, 103]
    assert trajectory(10, 1, 3) == [110, 120, 130]


def test_velocity_reports_px_per_second():
    m = model([[100, 100]], [10, 10], [[7.5, -5]])
    assert np.array_equal(m.velocities(), [[7.5, -5.0]])


# --- walls (paper sections II.E, II.F)


@pytest.mark.parametrize(
    "pos, vel, side, axis",
    [
        ([0, 50], [-10, 3], "left", 0),
        ([310, 50], [10, 3], "right", 0),
        ([50, 0], [3, -10], "top", 1),
        ([50, 230], [3, 10], "bottom", 1),
    ],
)
def test_each_wall_reverses_its_component_and_takes_the_step_back(pos, vel, side, axis):
    m = model([pos], [10, 10], [vel], fps=10)
    events = m.advance(1)  # the 3 px/s component fires only every 10th tick
    walls = [(int(e["a"]), SIDE_NAMES[e["code"]]) for e in events if e["type"] == EV_WALL]
    assert walls == [(0, side)]
    assert m.positions()[0, axis] == pos[axis]
    expected = np.array(vel, float)
    expected[axis] *= -1
    assert np.array_equal(m.velocities()[0], expected)


def test_a_box_at_the_wall_moving_inward_is_left_alone():
    m = model([[0, 0]], [10, 10], [[10, 10]])
    assert len(m.advance(5)) == 0
    assert np.array_equal(m.positions(), [[5, 5]])


# --- undo at most once per object per axis per tick


def test_displacement_is_taken_back_once_whatever_it_hit():
    # A (id 0) moves right into B (static, id 1); C (id 2) catches A from behind in the same tick.
    m = model(
        [[10, 100], [20, 100], [0, 100]],
        [10, 10],
        [[10, 0], [0, 0], [20, 0]],
        static=[False, True, False],
    )
    events = m.advance(1)
    assert [p[:3] for p in pairs_of(events)] == [(0, 1, "x"), (0, 2, "x")]
    x = m.positions()[:, 0]
    assert x[0] == 10  # taken back once, not twice (9)
    assert x[2] == 0
    # A's horizontal velocity flipped twice (back to +10), C's once
    assert np.array_equal(m.velocities()[:, 0], [10, 0, -20])


def test_wall_and_pair_in_one_tick_take_back_once():
    # A at the right wall moving right also runs into B sitting beside it vertically overlapping.
    m = model([[300, 100], [299, 108]], [[20, 10], [10, 10]], [[10, 10], [0, -10]])
    events = m.advance(1)
    kinds = [e["type"] for e in events]
    assert kinds[0] == EV_WALL
    assert EV_PAIR in kinds
    assert m.positions()[0, 0] == 300 and m.positions()[0, 1] == 100


# --- tunnelling (paper section III.A)


def test_tunnelling_at_1_fps_and_bounce_at_10_fps():
    one = model([[100, 115], [210, 115]], 10, [[10, 0], [-10, 0]], fps=1)
    assert pairs_of(one.advance(12)) == []
    assert one.positions()[0, 0] > one.positions()[1, 0]  # they passed each other
    ten = model([[100, 115], [210, 115]], 10, [[10, 0], [-10, 0]], fps=10)
    events = ten.advance(120)
    assert pairs_of(events) == [(0, 1, "x", 2, 10)]
    assert int(events[0]["tick"]) == 51
    assert ten.positions()[0, 0] < ten.positions()[1, 0]


# --- the broad phase changes nothing: the kernel equals the all-pairs reference

scene = st.integers(2, 14).flatmap(
    lambda n: st.tuples(
        st.lists(
            st.tuples(st.integers(0, 50), st.integers(0, 36)), min_size=n, max_size=n, unique=True
        ),
        st.lists(st.tuples(st.integers(1, 6), st.integers(1, 6)), min_size=n, max_size=n),
        st.lists(
            st.tuples(
                st.sampled_from([-20, -10, -5, -2.5, 0, 2.5, 5, 10, 20, 30]),
                st.sampled_from([-20, -10, -5, 0, 5, 7.5, 10, 20]),
            ),
            min_size=n,
            max_size=n,
        ),
        st.lists(st.booleans(), min_size=n, max_size=n),
    )
)


@settings(max_examples=60, deadline=None)
@given(scene)
def test_kernel_equals_the_all_pairs_reference(data):
    cells, size, vel, static = data
    # lay boxes on a 6 px grid so they start apart, inside a 320x240 world
    pos = [[6 * cx, 6 * cy] for cx, cy in cells]
    vel = [[0, 0] if s else list(v) for v, s in zip(vel, static, strict=True)]
    world = (306, 222)
    ref_pos, ref_step, ref_log = reference(pos, size, vel, 10, world, 80, static)
    m = Model(WorldSpec(*world, 10), Bodies.boxes(pos, size, vel, static=static))
    events = np.concatenate([m.advance(30), m.advance(1), m.advance(49)])
    assert logged(events) == ref_log
    assert m.positions().astype(int).tolist() == ref_pos
    assert m._S.step.tolist() == ref_step


def test_dense_crowd_equals_the_reference_and_logging_changes_nothing():
    rng = np.random.default_rng(3)
    cells = rng.choice(16 * 12, size=60, replace=False)
    pos = np.stack([cells % 16 * 10, cells // 16 * 10], axis=1)
    vel = rng.choice([-20, -10, 10, 20, 30], size=(60, 2))
    ref_pos, _, ref_log = reference(pos.tolist(), [[9, 9]] * 60, vel.tolist(), 10, (160, 120), 200)
    m = Model(WorldSpec(160, 120, 10), Bodies.boxes(pos, 9, vel))
    assert logged(m.advance(200)) == ref_log
    quiet = Model(WorldSpec(160, 120, 10), Bodies.boxes(pos, 9, vel))
    assert len(quiet.advance(200, log=False)) == 0
    assert np.array_equal(quiet.positions(), m.positions())
    assert m.positions().astype(int).tolist() == ref_pos


def test_reach_boxes_in_int64_give_the_int32_run(monkeypatch):
    """A world too large for int32 reach boxes keeps them in int64, with the same run."""
    from collide2d.engine.models.paper import model as paper

    rng = np.random.default_rng(3)
    cells = rng.choice(16 * 12, size=60, replace=False)
    pos = np.stack([cells % 16 * 10, cells // 16 * 10], axis=1)
    vel = rng.choice([-20, -10, 10, 20, 30], size=(60, 2))
    small = Model(WorldSpec(160, 120, 10), Bodies.boxes(pos, 9, vel))
    monkeypatch.setattr(paper, "REACH_INT32_MAX", 100)  # as if the world were far too large
    large = Model(WorldSpec(160, 120, 10), Bodies.boxes(pos, 9, vel))
    assert small._lists.reach.dtype == np.int32 and large._lists.reach.dtype == np.int64
    assert logged(small.advance(200)) == logged(large.advance(200))
    assert small.positions().tobytes() == large.positions().tobytes()
    assert paper._reach_dtype(WorldSpec(2**30, 100, 10), np.ones((1, 2)), np.ones((1, 2))) == (
        np.int64
    )


def test_far_jumps_fall_back_to_a_full_sort_and_stay_exact():
    # 60 px a tick in a 300 px world: the sweep order is reshuffled every tick
    rng = np.random.default_rng(5)
    cells = rng.choice(25 * 20, size=40, replace=False)
    pos = np.stack([cells % 25 * 12, cells // 25 * 12], axis=1)
    vel = rng.choice([-600, -300, 300, 600], size=(40, 2))
    ref_pos, _, ref_log = reference(pos.tolist(), [[8, 8]] * 40, vel.tolist(), 10, (300, 240), 60)
    m = Model(WorldSpec(300, 240, 10), Bodies.boxes(pos, 8, vel))
    assert logged(m.advance(60)) == ref_log
    assert m.positions().astype(int).tolist() == ref_pos


def test_refuses_fractional_positions_and_takes_no_geometry_or_substeps():
    with pytest.raises(ValueError, match="whole-pixel positions"):
        model([[1.5, 2]], 10, [[0, 0]])
    # every shape collides as its box, once per tick: the settings of the other models are errors
    with pytest.raises(TypeError, match="substeps"):
        Model(WorldSpec(100, 100, 10), Bodies.boxes([[0, 0]], 10, [[0, 0]]), substeps=2)
    with pytest.raises(TypeError, match="geometry"):
        Model(WorldSpec(100, 100, 10), Bodies.boxes([[0, 0]], 10, [[0, 0]]), geometry="exact")


# --- every broad phase, the skips and the resumable kernel change nothing


@settings(max_examples=15, deadline=None)
@given(scene, st.sampled_from(["sweep", "grid", "cells"]), st.booleans())
def test_every_broad_phase_and_no_skip_equal_the_reference(data, broadphase, skip):
    cells, size, vel, static = data
    pos = [[6 * cx, 6 * cy] for cx, cy in cells]
    vel = [[0, 0] if s else list(v) for v, s in zip(vel, static, strict=True)]
    world = (306, 222)
    ref_pos, ref_step, ref_log = reference(pos, size, vel, 10, world, 60, static)
    bodies = Bodies.boxes(pos, size, vel, static=static)
    m = Model(WorldSpec(*world, 10), bodies, broadphase=broadphase, skip=skip)
    assert logged(m.advance(60)) == ref_log
    assert m.positions().astype(int).tolist() == ref_pos
    assert m._S.step.tolist() == ref_step


def test_a_crowd_in_a_wide_world_agrees_across_methods_and_chunks():
    # 3,000 boxes in a wide world (the scene picks the grid); big steps at 60 fps make the list
    # anew nearly every tick; events large enough to outgrow the buffers several times
    rng = np.random.default_rng(12)
    n = 3000
    cells = rng.choice(150 * 110, size=n, replace=False)
    pos = np.stack([cells % 150 * 12, cells // 150 * 12], axis=1)
    vel = rng.integers(-100, 101, size=(n, 2))
    bodies = Bodies.boxes(pos, 10, vel)
    world = WorldSpec(1800, 1320, 60)
    runs = []
    for broadphase in (None, "sweep", "grid", "cells"):
        m = Model(world, bodies, broadphase=broadphase)
        events = m.advance(150)
        runs.append((events.tobytes(), m._S.pos.tobytes(), m._S.step.tobytes()))
    m = Model(world, bodies)
    events = np.concatenate([m.advance(k) for k in (1, 1, 48, 100)])
    runs.append((events.tobytes(), m._S.pos.tobytes(), m._S.step.tobytes()))
    assert all(r == runs[0] for r in runs)
    assert len(events) > 2000


def test_static_pairs_are_skipped_and_a_frozen_scene_has_no_pair_stage():
    # two static boxes that overlap would flip nothing but log a pair each tick; they are never
    # paired, while skip=False pairs them
    pos = [[10, 10], [15, 12], [100, 100]]
    bodies = Bodies.boxes(pos, 10, [[0, 0], [0, 0], [10, 0]], static=[True, True, False])
    world = WorldSpec(320, 240, 10)
    assert pairs_of(Model(world, bodies).advance(5)) == []
    assert len(pairs_of(Model(world, bodies, skip=False).advance(5))) == 5


def test_profile_runs_the_same_ticks_as_advance():
    rng = np.random.default_rng(4)
    cells = rng.choice(30 * 20, size=120, replace=False)
    pos = np.stack([cells % 30 * 10, cells // 30 * 10], axis=1)
    vel = rng.choice([-30, -10, 10, 20, 30], size=(120, 2))
    bodies = Bodies.boxes(pos, 8, vel)
    a, b = Model(WorldSpec(300, 200, 10), bodies), Model(WorldSpec(300, 200, 10), bodies)
    a.advance(80, log=False)
    spent = b.profile(80)
    # each stage of the one stage list of `_run`, by name, in the order the tick runs them
    assert tuple(spent) == tuple(name for name, _ in STAGES)
    assert tuple(spent) == ("move", "broad", "narrow", "response") and b.tick == 80
    assert all(v >= 0.0 for v in spent.values())
    assert a._S.pos.tolist() == b._S.pos.tolist() and a._S.step.tolist() == b._S.step.tolist()
    assert a._S.count.tolist() == b._S.count.tolist()
    assert a.event_counts() == b.event_counts() and min(a.event_counts()) > 0
    assert logged(a.advance(30)) == logged(b.advance(30))
