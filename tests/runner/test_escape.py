"""No name can break a terminal, a spreadsheet or a markdown table (runner/output/escape.py and the
outputs that use it): control characters and undecodable bytes reach a terminal spelled out, a
text cell of final.csv, results.csv or bench.csv never starts a formula while numbers stay
numbers, and a cell of results.md or bench.md stays one cell of one row."""

from __future__ import annotations

import csv
import io
import os
import re

import numpy as np
import pytest

from collide2d.runner.bench import report
from collide2d.runner.command import main
from collide2d.runner.output import files
from collide2d.runner.output.escape import VisibleStream, visible_streams
from collide2d.runner.output.progress import Progress
from collide2d.runner.sweep import results

SCENE = "version: 1\nworld: {width: 20, height: 20}\nticks: 2\nobjects: []\n"
# A spreadsheet runs these as formulas (or imports); each is text, none is a number.
FORMULAS = ["=1+1", "+cmd|' /C calc'!A0", "-2+3", "@SUM(A1)", "\t=1"]
# Text that is a plain number is a number to a spreadsheet too, and stays as it is.
NUMBERS = ["-980", "+5", "-1.5e-3", "-.5"]


def _cells(text: str) -> list[list[str]]:
    return list(csv.reader(io.StringIO(text)))


@pytest.mark.skipif(os.name == "nt", reason="file names hold control characters on POSIX only")
def test_control_characters_never_reach_the_terminal_raw(tmp_path, monkeypatch, capsys):
    """Found by hardening: a scenario's file name printed its escape sequences to the terminal
    (`\\e[2J` cleared the screen) and a carriage return let a name overwrite what was printed."""
    # ESC, CR, a C1 CSI, BEL, a byte that is not UTF-8
    raw = b"x\x1b[2J\rfake\xc2\x9b\x07\xff.yaml"
    monkeypatch.chdir(tmp_path)
    with open(raw, "w") as f:
        f.write(SCENE)  # refused: its stem cannot be a name
    assert main.main(["validate", os.fsdecode(raw)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("x\\x1b[2J\\rfake\\x9b\\x07\\xff.yaml:1:1: error: ")
    assert not re.search("[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff]", err)
    assert err.endswith("\n")  # newlines are still themselves


def test_a_progress_bar_still_draws_on_the_terminal_itself():
    terminal = io.StringIO()
    with visible_streams():
        bar = Progress(10, "run\x1b[2J", stream=VisibleStream(terminal))
        bar.update(5)
        bar.bar.refresh()  # drawn now, whatever its delays
        bar.close()
    shown = terminal.getvalue()
    assert "\r" in shown and "\x1b" not in shown and "run\\x1b[2J" in shown


def test_a_text_cell_never_starts_a_formula_and_numbers_stay_numbers(tmp_path):
    """Found by hardening: an object named `=HYPERLINK(...)` was a live formula in final.csv,
    and so were such values in a sweep's or a benchmark's table."""
    # a carriage return, which would split the row in many readers, is spelled out
    texts = FORMULAS + NUMBERS + ["plain", "", "\r=1", "two\nlines"]
    want = ["'" + t for t in FORMULAS] + NUMBERS + ["plain", "", "\\r=1", "two\nlines"]
    names = texts + [None]
    n = len(names)
    pos = np.column_stack([np.arange(n) - 5.0, np.zeros(n)])  # negative numbers too
    rows = _cells(files.final_csv_text(pos, -pos, names))
    assert rows[0] == ["id", "x", "y", "vx", "vy", "name"]
    assert [r[5] for r in rows[1:]] == [*want, ""]
    assert [r[1] for r in rows[1:6]] == ["-5", "-4", "-3", "-2", "-1"]

    columns = ["scenario", "note_text"]
    table = [
        {
            "scenario": text,
            "note_text": text,
            **{k: "" for k in results.FIGURES},
            "energy_drift": -0.25,
            "wall_events": -3,
            "note": text,
        }
        for text in texts
    ]
    rows = _cells(_written(results.write_csv, columns, table))[1:]
    assert [r[0] for r in rows] == [r[1] for r in rows] == [r[-2] for r in rows] == want
    for row in rows:
        assert row[2 + results.FIGURES.index("energy_drift")] == "-0.25"
        assert row[2 + results.FIGURES.index("wall_events")] == "-3"
    bench = [{"part": "peers", "model": t, "note": t, "ratio": -1.5, "n": -2} for t in texts]
    cells = [dict(zip(report.COLUMNS, r, strict=True)) for r in _cells(report.csv_text(bench))]
    assert [c["model"] for c in cells[1:]] == [c["note"] for c in cells[1:]] == want
    assert {(c["ratio"], c["n"]) for c in cells[1:]} == {("-1.5", "-2")}


def _written(write, *args) -> str:
    """What a results writer writes into a file, as text."""
    file = io.StringIO()
    write(file, *args)
    return file.getvalue()


def _table_rows(md: str) -> list[str]:
    return [line for line in md.splitlines() if line.startswith("|")]


def _cells_of(line: str) -> list[str]:
    """A markdown row's cells, split at the pipes that are not escaped."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]


def test_a_markdown_cell_stays_one_cell_of_one_row():
    """Found by hardening: a `|` or a line break in a value split a row of results.md or
    bench.md, shifting every column after it."""
    texts = ["a|b", "two\nlines", "back\\|slash", "tab\there", "\x1b[2J"]
    columns = ["scenario", "value"]
    table = [
        {"scenario": "s|x\ny", "value": t, **{k: "" for k in results.FIGURES}, "note": t}
        for t in texts
    ]
    md = _written(results.write_markdown, columns, table, len(texts), len(texts), True)
    rows = _table_rows(md)
    width = len(_cells_of(rows[0]))
    assert len(rows) == 2 + len(texts) and {len(_cells_of(r)) for r in rows} == {width}
    assert "## s|x\\ny" in md and "\x1b" not in md
    assert [_cells_of(r)[0] for r in rows[2:]] == [
        "a\\|b",
        "two\\\\nlines",
        "back\\\\\\|slash",
        "tab\\\\there",
        "\\\\x1b[2J",
    ]
    notes = [line for line in md.splitlines() if line.startswith("- ")]
    assert len(notes) == len(texts)  # each note one line

    bench = [{"part": "peers", "model": t, "n": 10, "ratio": 1.0, "note": t} for t in texts]
    rows = _table_rows(report.markdown(bench, "collide2d bench", 1.0))
    peers = [r for r in rows if "| 10 |" in r]
    assert len(peers) == len(texts)
    assert {len(_cells_of(r)) for r in peers} == {len(_cells_of(rows[-len(texts) - 2]))}
