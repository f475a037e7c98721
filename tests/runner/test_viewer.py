"""Tests of runner/output/viewerdata.py and engine/picture/sprites.py: the viewer's data is the
run's state, packed; its sprites paint what engine/picture/raster.py draws; long runs are refused
before they start; the file stays small."""

from __future__ import annotations

import base64
import json
import re
import zlib
from pathlib import Path

import numpy as np
import pytest

from collide2d.engine.picture.raster import render, round_positions
from collide2d.engine.picture.sprites import paint, sprites
from collide2d.runner.command import main
from collide2d.runner.output import viewerdata
from collide2d.runner.run import drive
from collide2d.runner.scenario.load import ScenarioError, load, loads

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = sorted(p.stem for p in (ROOT / "scenarios").glob("*.yaml"))


def _unpack(b64: str, dtype) -> np.ndarray:
    return np.frombuffer(
        zlib.decompress(base64.b64decode(b64)), dtype=np.dtype(dtype).newbyteorder("<")
    )


def _page_data(html: str) -> dict:
    text = re.search(r'<script id="data" type="application/json">(.*?)</script>', html, re.S)
    return json.loads(text.group(1).replace("<\\/", "</"))


@pytest.mark.parametrize("name", SCENARIOS)
def test_sprites_paint_the_frames_the_renderer_draws(name):
    scn = load(ROOT / "scenarios" / f"{name}.yaml")
    start, offsets = sprites(scn.bodies)
    rng = np.random.default_rng(1)
    for _ in range(3):  # fractional positions near and past the edges
        pos = scn.bodies.pos + rng.uniform(-40, 40, scn.bodies.pos.shape)
        want = render(scn.world, scn.bodies, pos)
        got = paint(
            scn.world.width,
            scn.world.height,
            scn.bodies.looks.color,
            start,
            offsets,
            round_positions(pos),
        )
        assert np.array_equal(got, want)


def test_viewer_data_is_every_ticks_rounded_state():
    scn = load(ROOT / "scenarios" / "unequal_masses.yaml", overrides={"ticks": 40})
    rec = viewerdata.Recorder(scn)
    seen_pos, seen_vel = [], []

    def both(model):
        rec.add(model)
        seen_pos.append(round_positions(model.positions()))
        seen_vel.append(model.velocities().astype(np.float32))

    drive(scn, on_tick=both, log_events=True, on_events=rec.events)
    data = _page_data(rec.page().decode())
    n, frames = scn.bodies.n, 41
    assert data["frames"] == frames and len(data["names"]) == n
    diffs = _unpack(data["positions"], np.int32).reshape(n, frames, 2)
    pos = np.cumsum(diffs, axis=1, dtype=np.int64).astype(np.int32)
    assert np.array_equal(pos, np.stack(seen_pos).transpose(1, 0, 2))
    vel = _unpack(data["velocities"], np.float32).reshape(n, frames, 2)
    assert np.array_equal(vel, np.stack(seen_vel).transpose(1, 0, 2))
    assert data["eventCount"] == len(data["events"]) > 0
    start, offsets = sprites(scn.bodies)
    assert data["spriteStart"] == start.tolist()
    assert np.array_equal(_unpack(data["sprites"], np.int32).reshape(-1, 2), offsets)


def test_stepping_one_tick_at_a_time_changes_nothing():
    scn = load(ROOT / "scenarios" / "circles_gas.yaml", overrides={"ticks": 50})
    a, _ = drive(scn, log_events=False)
    b, _ = drive(scn, log_events=False, on_tick=lambda model: None)
    assert np.array_equal(a.positions(), b.positions())
    assert np.array_equal(a.velocities(), b.velocities())


def test_a_run_too_long_to_view_is_refused_before_it_starts(tmp_path):
    text = (ROOT / "scenarios" / "paper_fifty_boxes.yaml").read_text()
    path = tmp_path / "long.yaml"
    path.write_text(text)
    argv = ["run", str(path), "--out", str(tmp_path / "out"), "--viewer", "--no-gif", "--quiet"]
    with pytest.raises(ScenarioError, match="past its limit of 20,000,000"):
        viewerdata.Recorder(load(path, overrides={"ticks": 1_000_000}))
    assert main.main([*argv, "--ticks", "1000000"]) == 2
    assert not (tmp_path / "out" / "long").exists()


def test_output_viewer_in_the_scenario_and_the_flag(tmp_path):
    base = (ROOT / "scenarios" / "fig2_case1.yaml").read_text()
    text = re.sub(
        r"(?m)^output: .*$", "output: {frames: none, gif: false, events: false, viewer: true}", base
    )
    assert loads(text).output.viewer and not loads(base).output.viewer
    path = tmp_path / "v.yaml"
    path.write_text(text)
    assert main.main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert sorted(p.name for p in (tmp_path / "out" / "v").iterdir()) == [
        "final.csv",
        "summary.json",
        "viewer.html",
    ]
    first = (tmp_path / "out" / "v" / "viewer.html").read_bytes()
    assert main.main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert (tmp_path / "out" / "v" / "viewer.html").read_bytes() == first  # same bytes
    assert "http" not in first.decode().replace("http-equiv", "")  # nothing from the network
    assert (
        main.main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet", "--no-viewer"]) == 0
    )
    assert not (tmp_path / "out" / "v" / "viewer.html").exists()


def test_no_name_can_end_or_comment_out_the_viewers_data(tmp_path):
    """Found by hardening: an object named `<!--<script>` kept the viewer from starting (the
    browser read the rest of the page as the data's script). The data holds no `<`, `>` or `&`
    as such, and reads back the very names."""
    names = ["<!--<script>", "</script><script>alert(1)</script>", "a & b", "]]> -->", "</SCRIPT/"]
    objects = "".join(
        f"  - {{shape: box, size: 2, position: [{4 * i}, 4], name: {json.dumps(name)}}}\n"
        for i, name in enumerate(names)
    )
    path = tmp_path / "v.yaml"
    path.write_text(f"version: 1\nworld: {{width: 40, height: 20}}\nticks: 3\nobjects:\n{objects}")
    out = tmp_path / "out"
    assert main.main(["run", str(path), "--out", str(out), "--quiet", "--viewer", "--no-gif"]) == 0
    page = (out / "v" / "viewer.html").read_text()
    head = '<script id="data" type="application/json">'
    data = page[page.index(head) + len(head) :]
    data = data[: data.index("</script>")]
    assert not set("<>&") & set(data)
    assert json.loads(data)["names"] == names


def test_ten_thousand_frames_of_fifty_objects_stay_small(tmp_path):
    argv = [
        "run",
        str(ROOT / "scenarios" / "paper_fifty_boxes.yaml"),
        "--ticks",
        "10000",
        "--out",
        str(tmp_path),
        "--viewer",
        "--no-gif",
        "--no-png",
        "--no-events",
        "--quiet",
    ]
    assert main.main(argv) == 0
    page = tmp_path / "paper_fifty_boxes" / "viewer.html"
    data = _page_data(page.read_text())
    assert data["frames"] == 10_001 and len(data["names"]) == 50
    assert page.stat().st_size < 1_500_000  # raw int32 positions alone would be 4 MB


def test_paper_viewer_keeps_each_pair_overlap_before_the_undo(tmp_path):
    path = ROOT / "scenarios" / "fig2_case1.yaml"
    assert main.main(["run", str(path), "--out", str(tmp_path), "--viewer", "--quiet"]) == 0
    data = _page_data((tmp_path / "fig2_case1" / "viewer.html").read_text())
    rows = _unpack(data["overlaps"], np.int32).reshape(-1, viewerdata.OVERLAP_COLUMNS)
    # tick 1: blue (0) moved down to y 101, green (1) up to y 110: 16 x 1 px overlap
    assert rows.tolist() == [[1, 0, 1, 16, 1, 104, 110, 120, 111, 100, 101, 104, 110]]
    assert data["paper"] and data["overlay"] == ["overlap"]


def test_the_viewer_opens_with_the_overlays_of_the_command_line(tmp_path):
    """`run --viewer --overlay velocity,contacts` opens with those checked (the data's `overlay`),
    not only the scenario's; `--overlay none` opens with none, even where the scenario asks."""
    path = ROOT / "scenarios" / "fig2_case1.yaml"  # its scenario asks for overlap
    argv = ["run", str(path), "--out", str(tmp_path), "--viewer", "--no-gif", "--quiet"]
    assert main.main([*argv, "--overlay", "contacts,velocity"]) == 0
    data = _page_data((tmp_path / "fig2_case1" / "viewer.html").read_text())
    assert data["overlay"] == ["velocity", "contacts"]
    assert main.main([*argv, "--overlay", "none"]) == 0
    data = _page_data((tmp_path / "fig2_case1" / "viewer.html").read_text())
    assert data["overlay"] == []
