"""runner.bench.error: the error measures against the exact model, the Pareto front, and the
stepped model converging on exact as substeps grow (docs/models.md#stepped)."""

from __future__ import annotations

import numpy as np
import pytest

from collide2d.engine import models
from collide2d.runner.bench import error
from collide2d.runner.bench.scenes import PROJECT_SCENARIOS
from collide2d.runner.scenario.load import load, loads


def test_pareto_marks_the_rows_nothing_beats_on_both_counts():
    rows = [
        {"run_time_s": 1.0, "error_long_px": 5.0},
        {"run_time_s": 2.0, "error_long_px": 1.0},
        {"run_time_s": 3.0, "error_long_px": 2.0},  # slower and worse than the second
        {"run_time_s": 0.5, "error_long_px": 9.0},
        {"run_time_s": 1.0, "error_long_px": 5.0},  # a tie is not beaten
        {"run_time_s": 4.0, "error_long_px": 1e-12},  # rounding: no closer than the floor
        {"run_time_s": 5.0, "error_long_px": 1e-13},  # slower, and no closer: beaten
    ]
    error.mark_pareto(rows)
    assert [r["pareto"] for r in rows] == ["yes", "yes", "no", "yes", "yes", "yes", "no"]


def test_the_quick_error_ladder_scores_the_reference_zero_and_finds_tunnelling():
    # bench_tunnelling over 2 s: the exact model is the reference; the paper model at 30 fps
    # lets the fast pairs through (the paper's section III.A), so it misses collisions
    rows = error.error_ladder(["bench_tunnelling"], ["exact", "paper"], True, lambda s: None)
    exact = [r for r in rows if r["part"] == "error" and r["model"] == "exact"]
    paper = {r["fps"]: r for r in rows if r["part"] == "error" and r["model"] == "paper"}
    assert exact and all(r["error_long_px"] == 0 and r["missed"] == 0 for r in exact)
    assert all(r["count_error"] == 0 and r["diverges_s"] is None for r in exact)
    assert all(r["max_penetration_px"] < 1e-9 for r in exact)
    assert paper[30]["missed"] > 0 and paper[30]["count_error"] < 0
    assert paper[30]["diverges_s"] is not None and paper[30]["diverges_s"] <= 0.5
    assert paper[30]["energy_drift"] == 0.0  # the flip rule keeps every speed
    timed = [r for r in rows if r["part"] == "error"]
    assert all(r["repeats"] >= 5 and r["run_time_min_s"] <= r["run_time_s"] for r in timed)
    assert all(r["run_time_s"] <= r["run_time_max_s"] for r in timed)
    assert {r["pareto"] for r in timed} <= {"yes", "no"} and "yes" in {r["pareto"] for r in timed}
    assert {r["part"] for r in rows} == {"error", "sensitivity"}


def test_the_quick_mass_ratio_chain_has_contacts():
    rows = error.error_ladder(["bench_mass_ratio_chain"], ["exact"], True, lambda s: None)
    assert rows[0]["pairs"] > 0 and rows[0]["long_s"] == 2.0


def test_missed_collisions_count_per_pair_and_the_sequences_part_there():
    # one head-on pair meeting at 0.3 s; at 2 fps the paper model jumps it over
    scenario = loads(
        "version: 1\nname: pair\nworld: {width: 200, height: 60, fps: 20}\nmodel: exact\n"
        "ticks: 10\nobjects:\n"
        "  - {shape: box, size: 10, position: [60, 20], velocity: [100, 0]}\n"
        "  - {shape: box, size: 10, position: [130, 20], velocity: [-100, 0]}\n"
    )
    ref = error._reference(scenario, (0.5,))
    assert sum(ref["pairs"].values()) == 1
    slow, _ = error._error_row(scenario, "paper", 2, 1, (0.5,), ref)
    fine, _ = error._error_row(scenario, "stepped", 20, 4, (0.5,), ref)
    assert (slow["missed"], slow["pairs"], slow["diverges_s"]) == (1, 0, pytest.approx(0.3))
    assert (fine["missed"], fine["pairs"], fine["diverges_s"]) == (0, 1, None)


def test_the_glancing_scan_finds_no_tunnelling_below_one_box_size_per_step():
    row = error.glancing(lambda s: None)
    assert row["value"] is None
    # and it does see tunnelling above: the smallest step that tunnels is at least one box size
    smallest = float(row["note"].rsplit(": ", 1)[1])
    assert smallest >= 1.0


def position_errors(name, substeps, horizons):
    """The stepped model's mean position error against exact at each horizon (s), on the scene
    as `collide2d run NAME --model stepped` loads it; errors below the contact tests' TIE_PX
    (1e-9 px, float rounding that grows with the number of steps) count as 0."""
    scenario = load(PROJECT_SCENARIOS / f"{name}.yaml", overrides={"model": "stepped"})
    world, bodies = scenario.world, scenario.bodies
    ref, _ = error.positions_at(models.make("exact", world, bodies), world.fps, horizons)
    out = []
    for s in substeps:
        m = models.make("stepped", world, bodies, substeps=s)
        at, _ = error.positions_at(m, world.fps, horizons)
        errs = [np.linalg.norm(a - r, axis=1).mean() for a, r in zip(at, ref, strict=True)]
        out.append([e if e > error.ERROR_FLOOR_PX else 0.0 for e in errs])
    return np.array(out).T  # one row per horizon


@pytest.mark.parametrize("name", ["bench_dense_gas", "bench_fast_small"])
def test_stepped_error_against_exact_falls_as_substeps_grow(name):
    # at 1 s and at 10 s, over 1, 4, 16 and 64 substeps: never rising, and falling overall from
    # above 1 px to below it (on the dense gas at 10 s with 64 substeps: the goal)
    horizons = (1.0, 10.0)
    for horizon, errs in zip(
        horizons, position_errors(name, (1, 4, 16, 64), horizons), strict=True
    ):
        # never rising by more than the models' own resolution (TIE_PX, 1e-9 px: past the
        # step where the error stops shrinking, what is left differs only in float rounding)
        assert all(b <= a + error.ERROR_FLOOR_PX for a, b in zip(errs[:-1], errs[1:], strict=True))
        assert errs[0] > 1.0 > errs[-1], (horizon, errs)


def events(*rows):
    from collide2d.engine.events import EV_PAIR, EV_WALL

    dtype = [("t", float), ("type", "i1"), ("a", "i4"), ("b", "i4")]
    return np.array([(t, EV_WALL if b < 0 else EV_PAIR, a, b) for t, a, b in rows], dtype=dtype)


def test_first_divergence_matches_each_pair_event_within_the_window_in_any_order():
    ref = events((0.10, 0, 1), (0.10, 1, 2), (0.31, 0, 1), (0.5, 3, -1), (0.90, 2, 3))
    # the same contacts, logged at tick ends, the two at one instant the other way round
    same = events((0.15, 1, 2), (0.15, 0, 1), (0.35, 0, 1), (0.95, 2, 3))
    assert error.first_divergence(ref, same, 0.1) is None
    # one contact late by more than the window: they part at the earlier of the two
    late = events((0.15, 1, 2), (0.15, 0, 1), (0.45, 0, 1), (0.95, 2, 3))
    assert error.first_divergence(ref, late, 0.1) == pytest.approx(0.31)
    # an extra contact in the run, and a missing one at the end
    extra = events((0.15, 1, 2), (0.15, 0, 1), (0.2, 4, 5), (0.35, 0, 1))
    assert error.first_divergence(ref, extra, 0.1) == pytest.approx(0.2)
    assert error.first_divergence(ref, same[:3], 0.1) == pytest.approx(0.9)


def test_position_error_is_the_mean_distance_of_the_objects():
    pos = np.array([[0.0, 0.0], [3.0, 4.0]])
    ref = np.array([[0.0, 0.0], [0.0, 0.0]])
    assert error.position_error(pos, ref) == 2.5
    assert error.position_error(np.empty((0, 2)), np.empty((0, 2))) == 0.0
