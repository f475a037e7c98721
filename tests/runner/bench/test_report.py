"""runner.bench.report: bench.csv's columns and the headline ratios."""

from __future__ import annotations

import csv
import io

from collide2d.runner.bench import report


def test_csv_has_the_columns_and_blanks_where_they_do_not_apply():
    rows = [
        {"part": "scaling", "model": "stepped", "n": 50, "steps_per_s": 1234.5},
        {"part": "skips", "with_s": 0.5, "without_s": 2.0, "saving": 4.0, "note": "a, b"},
    ]
    text = report.csv_text(rows)
    lines = text.splitlines()
    assert lines[0].split(",") == list(report.COLUMNS)
    assert len(lines) == 3
    parsed = list(csv.DictReader(io.StringIO(text)))
    assert parsed[0]["steps_per_s"] == "1234.5" and parsed[0]["saving"] == ""
    assert parsed[1]["note"] == "a, b"


def test_headline_gives_the_ratios_the_issue_asks_for_with_target_and_mark():
    rows = [
        {"part": "scaling", "model": "stepped", "n": 1_000, "ns_per_body_step": 20.0},
        {"part": "scaling", "model": "stepped", "n": 100_000, "ns_per_body_step": 30.0},
        {"part": "peers", "model": "pymunk", "n": 1_000, "ratio": 4.5},
        {"part": "targets", "value": 1_200_000.0, "note": "section IV demo headless",
         "target": ">= 1,000,000", "met": True, "noisy": "no", "spread": 0.05},
        {"part": "skips", "noisy": "yes", "spread": 0.35},
        {"part": "error", "model": "stepped", "scene": "bench_dense_gas", "fps": 60,
         "substeps": 64, "short_s": 1.0, "long_s": 10.0, "error_short_px": 0.1,
         "error_long_px": 0.5, "run_time_s": 0.2, "run_time_min_s": 0.19, "run_time_max_s": 0.22,
         "noisy": "no", "spread": 0.15, "diverges_s": None, "pairs": 10, "missed": 0,
         "count_error": 0, "energy_drift": 0.0, "max_penetration_px": 0.0, "pareto": "yes"},
        {"part": "glancing", "value": None, "scene": "two boxes", "fps": 60, "note": "none"},
        {"part": "scaling", "model": "paper", "n": 100_000, "steps_per_s": 310.0},
        {"part": "peers", "model": "pymunk", "n": 100_000, "ratio": 31.0},
        {"part": "exact", "scene": "two-body chain", "value": 3_900_000.0},
        {"part": "exact", "scene": "standard-10000", "value": 510_000.0},
        {"part": "load", "how": "CSV table", "n": 100_000, "value": 0.25, "peak_mb": 400.0},
        {"part": "load", "how": "YAML list, fast lane", "n": 100_000, "value": 0.6,
         "peak_mb": 320.0},
        {"part": "load", "how": "YAML block list, fast lane", "n": 100_000, "value": 3.2,
         "peak_mb": 200.0},
    ]  # fmt: skip
    head = {what: (figure, target, met) for what, figure, target, met in report.headline(rows)}
    assert head["stepped / pymunk steps/s, N = 1,000"] == ("4.50", ">= 10", "✗")
    assert head["stepped cost per body-step, N = 100,000 / N = 1,000"] == ("1.50", "<= 2", "✓")
    assert head["stepped / pymunk steps/s, N = 100,000"] == ("31.00", ">= 30", "✓")
    assert head["stepped ns per body-step, N = 100,000"] == ("30.0", "<= 10", "✗")
    assert head["paper steps/s, N = 100,000"] == ("310", ">= 300", "✓")
    assert head["exact events/s, two-body chain"] == ("3,900,000", ">= 4,000,000", "✗")
    assert head["exact events/s, standard-10000"] == ("510,000", ">= 500,000", "✓")
    assert head["load 100,000 objects, CSV table"] == ("0.25 s, 400 MB", "<= 0.3 s", "✓")
    assert head["load 100,000 objects, YAML list, fast lane"] == (
        "0.60 s, 320 MB",
        "<= 1 s, <= 300 MB",
        "✗",
    )
    assert head["load 100,000 objects, YAML block list, fast lane"] == (
        "3.20 s, 200 MB",
        "<= 3 s, <= 300 MB",
        "✗",
    )
    assert head["section IV demo headless"] == ("1,200,000", ">= 1,000,000", "✓")
    assert head["stepped error at 10 s, bench_dense_gas, 64 substeps"] == ("0.5 px", "< 1 px", "✓")
    assert head["glancing tunnelling at 1 substep below one box size per step"][2] == "✓"
    assert head["timings marked noisy (spread > 20 %)"] == ("1 of 3", "0", "✗")
    assert head["largest repeat spread (max - min) / median"][0] == "35%"
    md = report.markdown(rows, "collide2d bench", 1.0)
    assert "| what | figure | target | met |" in md and "| 4.50 | >= 10 | ✗ |" in md
    assert "| bench_dense_gas | stepped | 60 | 64 | 200 | 190-220 | no | 0.1 | 0.5 |" in md
