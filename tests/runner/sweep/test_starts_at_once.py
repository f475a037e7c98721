"""A sweep of many seeds starts its runs at once, each run still checked before it is sent: the
seeds' drawings are checked in the background, ahead of the runs, and a seed refused while runs
are going stops the sweep with the located error a refusal up front gives, nothing written."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from collide2d.runner.command.main import main
from collide2d.runner.scenario import generate as gen
from collide2d.runner.sweep import results

from .planned import CRAMPED

pytest.importorskip("distributed")

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
FIFTY = str(SCENARIOS / "paper_fifty_boxes.yaml")
# The longest the first run's result may take to come back (an embedded cluster of one worker
# process starting on a busy machine): a check held back until then never waits longer.
FIRST_RESULT_S = 90
# seeds that place CRAMPED's boxes, and one that does not
PLACED = (4, 29, 34, 41, 55, 66, 71, 81, 85, 93, 113, 118, 127, 142, 147, 149)
REFUSED = 154


def _held_back(monkeypatch, seed: int) -> dict:
    """In this process (the sweep's, not its workers'), the drawing of `seed` waits until the
    sweep has taken a run's result (or FIRST_RESULT_S); what it saw is returned in the dict."""
    seen = {"drawn": 0, "first_result_before": None, "drawn_at_first_result": None}
    taken = threading.Event()
    generate, take = gen.generate, results.Table.take

    def drawing(width, height, pos, size, blocks):
        if blocks and blocks[0].seed == seed and seen["first_result_before"] is None:
            seen["first_result_before"] = taken.wait(FIRST_RESULT_S)
        drawn = generate(width, height, pos, size, blocks)
        seen["drawn"] += 1
        return drawn

    def taking(table, run, figures, positions):
        if not taken.is_set():
            seen["drawn_at_first_result"] = seen["drawn"]
            taken.set()
        return take(table, run, figures, positions)

    monkeypatch.setattr(gen, "generate", drawing)
    monkeypatch.setattr(results.Table, "take", taking)
    return seen


def test_the_first_runs_come_back_before_the_last_seed_is_checked(tmp_path, monkeypatch):
    seen = _held_back(monkeypatch, 1000)
    out = tmp_path / "out"
    args = ["sweep", FIFTY, "--set", "ticks=1", "--seeds", "1-1000", "--workers", "1", "--quiet"]
    assert main([*args, "--out", str(out)]) == 0
    # the check of seed 1,000 could wait for a run's result: the runs did not wait for it; the
    # seeds drawn by then are at most the 999 others, the sweep's own load and its first seed's
    assert seen["first_result_before"] is True, seen
    assert seen["drawn_at_first_result"] <= 1001, seen
    rows = (out / "sweep" / "results.csv").read_text().splitlines()
    assert len(rows) == 1001 and rows[-1].startswith("paper_fifty_boxes,1000,paper,")


def test_a_seed_refused_while_runs_go_is_the_located_error_and_nothing_is_written(
    tmp_path, monkeypatch, capsys
):
    path = tmp_path / "cramped.yaml"
    path.write_text(CRAMPED)
    out = tmp_path / "out"
    seeds = ",".join(str(s) for s in PLACED)
    args = ["sweep", str(path), "--workers", "1", "--quiet", "--out", str(out)]
    # refused in the first batch: not a folder made
    assert main([*args, "--seeds", f"4,{REFUSED}"]) == 2
    said = f"{path}:6:5: error: in the sweep run seed={REFUSED}: generate[0]: cannot place 3 "
    assert capsys.readouterr().err.startswith(said)
    assert not out.exists()
    assert main([*args, "--seeds", seeds]) == 0  # a sweep before, which the refused one keeps
    before = (out / "sweep" / "results.csv").read_text()
    assert len(before.splitlines()) == 1 + len(PLACED)
    capsys.readouterr()
    seen = _held_back(monkeypatch, REFUSED)
    assert main([*args, "--seeds", f"{seeds},{REFUSED}"]) == 2
    assert seen["first_result_before"] is True, seen  # refused once runs had come back
    err = capsys.readouterr().err
    # the message a refusal before any run gave: located at the block, naming the run
    assert err.startswith(said), err
    assert len(err.strip().splitlines()) == 1, err
    assert (out / "sweep" / "results.csv").read_text() == before
    assert sorted(p.name for p in out.iterdir()) == ["sweep"]  # no lock or staging left
