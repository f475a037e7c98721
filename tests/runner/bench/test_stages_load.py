"""runner.bench.stages and load (`--part stages`, `--part load`): quick runs, one row per figure."""

from __future__ import annotations

from collide2d.engine import threads
from collide2d.runner.bench import load, peers, stages
from collide2d.runner.scenario import fastlane
from collide2d.runner.scenario.load import load as load_scenario


def quiet(_text):
    pass


def test_quick_stages_part_times_each_stage_on_one_thread_and_all():
    before = threads.threads()
    rows = stages.stages(True, quiet, ns=[200])
    timed = [r for r in rows if "steps_per_s" in r]
    counts = sorted({1, threads.available()})
    assert [(r["model"], r["note"].split(";")[0]) for r in timed] == [
        (m, f"steps/s on {t} thread(s)") for m in stages.STAGE_MODELS for t in counts
    ]
    for r in timed:
        assert r["n"] == 200 and r["steps_per_s"] > 0
        assert all(f"{s} " in r["note"] for s in ("move", "broad", "narrow", "response"))
    ratios = [r for r in rows if "ratio" in r and "pymunk" not in r["note"]]
    assert len(ratios) == (2 if threads.available() > 1 else 0)
    if peers.pymunk_available():
        assert sum("pymunk" in r["note"] for r in rows) == len(counts)
    assert threads.threads() == before  # the thread count is put back


def test_quick_load_part_loads_the_same_objects_four_ways(tmp_path):
    rows = load.load(True, quiet, n=300)
    assert [r["scene"].split(": ")[1] for r in rows] == [
        "YAML list, fast lane",
        "YAML block list, fast lane",
        "CSV table",
        "YAML list, general path",
    ]
    assert all(r["n"] == 300 and r["run_time_s"] > 0 and "peak memory" in r["note"] for r in rows)
    paths = load.write_scenes(tmp_path, 1000)
    assert all(fastlane.split(paths[k].read_text()) is not None for k in ("yaml", "block"))
    a, b, c = (load_scenario(paths[k]) for k in ("yaml", "csv", "block"))
    for other in (b, c):
        assert a.bodies.pos.tobytes() == other.bodies.pos.tobytes()
        assert a.bodies.vel.tobytes() == other.bodies.vel.tobytes()
        assert a.palette.tobytes() == other.palette.tobytes()
