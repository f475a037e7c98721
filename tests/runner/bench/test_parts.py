"""runner.bench.paper, exact and raster: the parts asked for with `--part`, each a quick run with
one row per figure, and the path the raster part draws; the targets part's runs have bytecode
cached as an installation has it."""

from __future__ import annotations

import numpy as np

from collide2d.runner.bench import exact, paper, raster
from collide2d.runner.bench.scenes import chain_scene
from collide2d.runner.command.main import main
from collide2d.runner.scenario.load import loads


def quiet(_text):
    pass


def test_quick_paper_part_times_the_demo_three_ways():
    rows = paper.paper(True, quiet)
    assert [r["note"].split(",")[0] for r in rows] == [
        "headless",
        "headless",
        "through runner.run.drive",
    ]
    assert all(r["scene"] == "paper_fifty_boxes" and r["n"] == 50 and r["value"] > 0 for r in rows)


def test_quick_exact_part_counts_events_per_second():
    rows = exact.exact(True, quiet)
    assert [r["scene"] for r in rows] == ["two-body chain", f"standard-{exact.QUICK_EXACT_GAS_N}"]
    assert rows[0]["n"] == 2 and all(r["events_per_s"] > 0 for r in rows)


def test_the_chain_scene_is_two_boxes_at_1e5_px_per_s():
    scenario = loads(chain_scene())
    assert scenario.bodies.n == 2 and scenario.model == "exact"
    assert scenario.bodies.vel[:, 0].tolist() == [1e5, -1.5e5]


def test_the_raster_path_moves_one_px_a_frame_inside_the_world():
    start = np.array([[0.0, 0.0], [100.0, 50.0], [20.0, 20.0]])
    size = np.full((3, 2), 10.0)
    path = raster.moving_positions(start, size, 120, 70, 300, movers=2)
    assert path.shape == (300, 3, 2)
    assert np.all(path >= 0) and np.all(path + size <= [120, 70])
    assert np.all(np.abs(np.diff(path[:, :2], axis=0)) == 1.0)
    assert np.all(path[:, 2] == start[2])


def test_quick_raster_part_through_the_command_line(tmp_path):
    assert main(["bench", "--quick", "--part", "raster", "--out", str(tmp_path), "--quiet"]) == 0
    md = (tmp_path / "bench" / "bench.md").read_text()
    assert "## Drawing and writing frames" in md and "one PNG frame" in md
    csv = (tmp_path / "bench" / "bench.csv").read_text().splitlines()
    assert len(csv) == 1 + 6 and all(line.startswith("raster,") for line in csv[1:])


def test_small_runs_are_timed_with_bytecode_cached_apart_from_the_sources(tmp_path, monkeypatch):
    import subprocess
    import sys

    from collide2d.runner.bench.targets import user_env

    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")  # as some CI images set it
    env = user_env(str(tmp_path / "pycache"))
    code = "import sys, collide2d.runner.bench.scenes; print(sys.dont_write_bytecode)"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"
    assert list((tmp_path / "pycache").rglob("scenes.*.pyc"))  # written under the prefix
