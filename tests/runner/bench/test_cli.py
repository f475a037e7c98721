"""`collide2d bench`: a tiny run of a part (`--quick`, small N) through the command line, peers
without pymunk, and a scenarios folder that lacks the benchmark scenarios."""

from __future__ import annotations

import csv
import math

import pytest

from collide2d.runner.bench import peers
from collide2d.runner.command.main import main


def rows_of(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


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


def test_peers_without_pymunk_say_so_and_still_succeed(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(peers, "pymunk_available", lambda: False)
    code = main(["bench", "--quick", "--part", "peers", "--out", str(tmp_path), "--quiet"])
    assert code == 0
    assert "pymunk is not installed" in capsys.readouterr().err
    assert (tmp_path / "bench" / "bench.csv").exists()


def test_a_folder_without_the_benchmark_scenarios_is_refused(tmp_path, capsys):
    code = main(["bench", "--quick", "--part", "error", "--scenarios", str(tmp_path)])
    assert code == 2
    assert "lacks bench_tunnelling.yaml" in capsys.readouterr().err
    assert not (tmp_path / "bench").exists()


def test_pymunk_is_timed_in_turn_with_the_stepped_runs(tmp_path, monkeypatch):
    """With --peers, each round of the stepped model's timings times pymunk once, between its
    1-tick run and its full run (in either order), and the ratio divides the two medians."""
    pytest.importorskip("pymunk")
    from collide2d.runner.bench import scaling

    timeline = []

    def drive_seconds(text, ticks):
        timeline.append("1 tick" if ticks == 1 else "run")
        return 0.001 if ticks == 1 else 0.5

    class Peer:
        how = "bounding-box tree"
        rates = iter([900.0, 1000.0, 1100.0])

        def sample(self):
            timeline.append("pymunk")
            return next(self.rates)

    monkeypatch.setattr(scaling, "drive_seconds", drive_seconds)
    monkeypatch.setattr(peers, "timer", lambda quick: lambda n: Peer())
    code = main(
        ["bench", "--quick", "--peers", "--part", "scaling", "--n", "40", "--model", "stepped"]
        + ["--out", str(tmp_path), "--quiet"]
    )
    assert code == 0
    rounds = [timeline[k : k + 3] for k in range(0, len(timeline), 3)]
    assert rounds == [
        ["1 tick", "pymunk", "run"],
        ["run", "pymunk", "1 tick"],
        ["1 tick", "pymunk", "run"],
    ]
    rows = rows_of(tmp_path / "bench" / "bench.csv")
    ours = next(r for r in rows if r["part"] == "scaling")
    peer = next(r for r in rows if r["part"] == "peers")
    assert float(peer["steps_per_s"]) == 1000.0
    assert math.isclose(float(peer["ratio"]), float(ours["steps_per_s"]) / 1000.0, rel_tol=1e-9)
    assert "timed in turn" in peer["note"]
