"""`collide2d bench`: the standard scene, the error measures, the Pareto front, the reports, and a
tiny run of each part (`--quick`, small N) through the command line."""

from __future__ import annotations

import csv
import math
import sys

import numpy as np
import pytest

from collide2d.runner import bench
from collide2d.runner.cli import main
from collide2d.runner.scenario import loads


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# --- the standard scene -------------------------------------------------------------------------


@pytest.mark.parametrize("n", [50, 1_000, 10_000, 100_000])
def test_standard_world_is_4_to_3_with_boxes_on_5_percent(n):
    width, height = bench.standard_world(n)
    assert abs(width / height - 4 / 3) < 2 / height
    covered = n * 100 / (width * height)
    assert abs(covered - 0.05) < 0.05 * 2 / min(width, height) * 2


def test_standard_world_at_100k_fits_the_default_side_limit():
    assert bench.standard_world(100_000) == (16330, 12248)


def test_standard_scene_is_seeded_boxes_at_10_to_100_px_per_s():
    a = loads(bench.standard_scene(200, "stepped"))
    b = loads(bench.standard_scene(200, "stepped"))
    assert a.bodies.n == 200 and a.world.fps == 60
    assert np.array_equal(a.bodies.pos, b.bodies.pos) and np.array_equal(a.bodies.vel, b.bodies.vel)
    speed = np.hypot(*a.bodies.vel.T)
    assert speed.min() >= 10 and speed.max() <= 100
    assert (a.bodies.size == 10).all()
    paper = loads(bench.standard_scene(200, "paper"))
    assert np.array_equal(paper.bodies.vel, np.floor(paper.bodies.vel))  # whole px/s


# --- the error measures ---------------------------------------------------------------------------


def test_max_penetration_is_the_deepest_overlap():
    pos = np.array([[0.0, 0.0], [7.0, 2.0], [50.0, 50.0], [58.0, 50.0]])
    size = np.full((4, 2), 10.0)
    # pair (0, 1) overlaps 3 x 8 -> 3; pair (2, 3) overlaps 2 x 10 -> 2
    assert bench.max_penetration(pos, size) == 3.0
    assert bench.max_penetration(pos[[0, 2]], size[:2]) == 0.0
    touching = np.array([[0.0, 0.0], [10.0, 0.0]])
    assert bench.max_penetration(touching, size[:2]) == 0.0


def test_pareto_marks_the_rows_nothing_beats_on_both_counts():
    rows = [
        {"run_time_s": 1.0, "position_error_px": 5.0},
        {"run_time_s": 2.0, "position_error_px": 1.0},
        {"run_time_s": 3.0, "position_error_px": 2.0},  # slower and worse than the second
        {"run_time_s": 0.5, "position_error_px": 9.0},
        {"run_time_s": 1.0, "position_error_px": 5.0},  # a tie is not beaten
    ]
    bench._mark_pareto(rows)
    assert [r["pareto"] for r in rows] == ["yes", "yes", "no", "yes", "yes"]


def test_the_error_ladder_scores_the_reference_zero_and_finds_tunnelling():
    # bench_tunnelling over 0.5 s: the exact model is the reference; the paper model at 30 fps
    # lets the fast pairs through (the paper's section III.A), so it misses collisions
    rows = bench.error_ladder(["bench_tunnelling"], ["exact", "paper"], True, lambda s: None)
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
    ref = bench._reference(scenario, 0.5)
    assert sum(ref["pairs"].values()) == 1
    slow = bench._error_row(scenario, "paper", 2, 1, 0.5, ref, 1)
    fine = bench._error_row(scenario, "stepped", 20, 4, 0.5, ref, 1)
    assert (slow["missed"], slow["pairs"]) == (1, 0)
    assert (fine["missed"], fine["pairs"]) == (0, 1)


# --- the reports ----------------------------------------------------------------------------------


def test_csv_has_the_columns_and_blanks_where_they_do_not_apply():
    rows = [
        {"part": "scaling", "model": "stepped", "n": 50, "steps_per_s": 1234.5},
        {"part": "skips", "with_s": 0.5, "without_s": 2.0, "saving": 4.0, "note": "a, b"},
    ]
    text = bench.csv_text(rows)
    lines = text.splitlines()
    assert lines[0].split(",") == list(bench.COLUMNS)
    assert len(lines) == 3
    import io

    parsed = list(csv.DictReader(io.StringIO(text)))
    assert parsed[0]["steps_per_s"] == "1234.5" and parsed[0]["saving"] == ""
    assert parsed[1]["note"] == "a, b"


def test_headline_gives_the_ratios_the_issue_asks_for():
    rows = [
        {"part": "scaling", "model": "stepped", "n": 1_000, "ns_per_body_step": 20.0},
        {"part": "scaling", "model": "stepped", "n": 100_000, "ns_per_body_step": 30.0},
        {"part": "peers", "model": "pymunk", "n": 1_000, "ratio": 6.5},
        {"part": "targets", "value": 1_200_000.0, "note": "section IV demo headless"},
    ]
    head = dict(bench.headline(rows))
    assert head["stepped / pymunk steps/s, N = 1,000 (target >= 5)"] == "6.50"
    assert head["stepped cost per body-step, N = 100,000 / N = 1,000 (target <= 2)"] == "1.50"
    assert head["section IV demo headless"] == "1,200,000"


def test_quick_scaling_through_the_command_line_writes_csv_and_markdown(tmp_path, capsys):
    code = main(
        ["bench", "--quick", "--part", "scaling", "--n", "40", "--model", "stepped"]
        + ["--model", "paper", "--out", str(tmp_path)]
    )
    assert code == 0
    folder = tmp_path / "bench"
    rows = rows_of(folder / "bench.csv")
    assert [(r["part"], r["model"], r["n"]) for r in rows] == [
        ("scaling", "stepped", "40"),
        ("scaling", "paper", "40"),
    ]
    for r in rows:
        steps = float(r["steps_per_s"])
        assert steps > 0 and math.isclose(float(r["body_steps_per_s"]), 40 * steps, rel_tol=1e-5)
        assert float(r["move_ms"]) >= 0 and float(r["render_ms"]) > 0
    md = (folder / "bench.md").read_text()
    assert "## Scaling: the standard scene" in md and "| stepped | 40 |" in md
    assert "bench: 2 rows" in capsys.readouterr().out


def test_without_matplotlib_the_csv_and_markdown_still_come_out(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    rows = [{"part": "error", "scene": "s", "model": "exact", "run_time_s": 0.1}]
    assert bench.plots(rows, tmp_path) == []
    assert list(tmp_path.iterdir()) == []


def test_plots_are_written_with_matplotlib(tmp_path):
    pytest.importorskip("matplotlib")
    rows = [
        {"part": "scaling", "model": "stepped", "n": 50, "steps_per_s": 100.0},
        {"part": "scaling", "model": "stepped", "n": 500, "steps_per_s": 10.0},
        {"part": "error", "scene": "s", "model": "exact", "run_time_s": 0.1,
         "position_error_px": 0.0, "pareto": "yes"},
        {"part": "error", "scene": "s", "model": "paper", "run_time_s": 0.01,
         "position_error_px": 3.0, "pareto": "yes"},
    ]  # fmt: skip
    assert bench.plots(rows, tmp_path) == ["scaling.png", "runtime_vs_error.png"]
    assert (tmp_path / "runtime_vs_error.png").read_bytes()[:4] == b"\x89PNG"


def test_peers_without_pymunk_say_so_and_still_succeed(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(bench, "pymunk_available", lambda: False)
    code = main(["bench", "--quick", "--part", "peers", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    assert "pymunk is not installed" in capsys.readouterr().err
    assert (tmp_path / "bench" / "bench.csv").exists()


def test_pymunk_steps_the_same_standard_scene():
    pymunk = pytest.importorskip("pymunk")
    scenario = loads(bench.standard_scene(30, "stepped"))
    space = bench._pymunk_space(scenario, hashed=False)
    assert len(space.bodies) == 30 and len(space.shapes) == 30 + 4
    body = list(space.bodies)[0]
    assert body.moment == math.inf and body.mass == 1.0
    assert tuple(body.velocity) == tuple(scenario.bodies.vel[0])
    rate, how = bench.pymunk_steps_per_second(30, 0.01, 1)
    assert rate > 0 and how in ("spatial hash", "bounding-box tree")
    assert pymunk.version


def test_quick_skips_measure_each_skip(tmp_path):
    rows = bench.skips(True, lambda s: None)
    names = [r["note"] for r in rows]
    assert "no rasterising when no frame is asked for" in names
    assert "erase only what moved" in names
    assert "exact re-predicts only what an event touched" in names
    assert any("between static objects" in n for n in names)
    assert all(r["with_s"] > 0 and r["without_s"] > 0 for r in rows)


def test_a_folder_without_the_benchmark_scenarios_is_refused(tmp_path, capsys):
    code = main(["bench", "--quick", "--part", "error", "--scenarios", str(tmp_path)])
    assert code == 2
    assert "lacks bench_tunnelling.yaml" in capsys.readouterr().err
    assert not (tmp_path / "bench").exists()
