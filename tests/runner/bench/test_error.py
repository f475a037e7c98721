"""runner.bench.error: the error measures against the exact model, and the Pareto front."""

from __future__ import annotations

from collide2d.runner.bench import error
from collide2d.runner.scenario import loads


def test_pareto_marks_the_rows_nothing_beats_on_both_counts():
    rows = [
        {"run_time_s": 1.0, "position_error_px": 5.0},
        {"run_time_s": 2.0, "position_error_px": 1.0},
        {"run_time_s": 3.0, "position_error_px": 2.0},  # slower and worse than the second
        {"run_time_s": 0.5, "position_error_px": 9.0},
        {"run_time_s": 1.0, "position_error_px": 5.0},  # a tie is not beaten
    ]
    error.mark_pareto(rows)
    assert [r["pareto"] for r in rows] == ["yes", "yes", "no", "yes", "yes"]


def test_the_error_ladder_scores_the_reference_zero_and_finds_tunnelling():
    # bench_tunnelling over 0.5 s: the exact model is the reference; the paper model at 30 fps
    # lets the fast pairs through (the paper's section III.A), so it misses collisions
    rows = error.error_ladder(["bench_tunnelling"], ["exact", "paper"], True, lambda s: None)
    exact = [r for r in rows if r["model"] == "exact"]
    paper = {r["fps"]: r for r in rows if r["model"] == "paper"}
    assert exact and all(r["position_error_px"] == 0 and r["missed"] == 0 for r in exact)
    assert all(r["count_error"] == 0 and r["max_penetration_px"] < 1e-9 for r in exact)
    assert paper[30]["missed"] > 0 and paper[30]["count_error"] < 0
    assert paper[30]["missed"] >= paper[60]["missed"]
    assert paper[30]["energy_drift"] == 0.0  # the flip rule keeps every speed
    assert {r["pareto"] for r in rows} <= {"yes", "no"} and "yes" in {r["pareto"] for r in rows}


def test_missed_collisions_count_per_pair():
    # one head-on pair meeting at 0.3 s; at 2 fps the paper model jumps it over
    scenario = loads(
        "version: 1\nname: pair\nworld: {width: 200, height: 60, fps: 20}\nmodel: exact\n"
        "ticks: 10\nobjects:\n"
        "  - {shape: box, size: 10, position: [60, 20], velocity: [100, 0]}\n"
        "  - {shape: box, size: 10, position: [130, 20], velocity: [-100, 0]}\n"
    )
    ref = error._reference(scenario, 0.5)
    assert sum(ref["pairs"].values()) == 1
    slow = error._error_row(scenario, "paper", 2, 1, 0.5, ref, 1)
    fine = error._error_row(scenario, "stepped", 20, 4, 0.5, ref, 1)
    assert (slow["missed"], slow["pairs"]) == (1, 0)
    assert (fine["missed"], fine["pairs"]) == (0, 1)
