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


def test_headline_gives_the_ratios_the_issue_asks_for():
    rows = [
        {"part": "scaling", "model": "stepped", "n": 1_000, "ns_per_body_step": 20.0},
        {"part": "scaling", "model": "stepped", "n": 100_000, "ns_per_body_step": 30.0},
        {"part": "peers", "model": "pymunk", "n": 1_000, "ratio": 6.5},
        {"part": "targets", "value": 1_200_000.0, "note": "section IV demo headless"},
    ]
    head = dict(report.headline(rows))
    assert head["stepped / pymunk steps/s, N = 1,000 (target >= 5)"] == "6.50"
    assert head["stepped cost per body-step, N = 100,000 / N = 1,000 (target <= 2)"] == "1.50"
    assert head["section IV demo headless"] == "1,200,000"
