"""Tests of runner/golden/report.py: diff images, report folders, self-contained pages."""

from __future__ import annotations

import json
import re

import numpy as np

from collide2d.runner.golden import report
from collide2d.runner.golden.compare import compare_frame
from collide2d.runner.golden.serialize import decode_png


def _pair():
    e = np.full((4, 6, 3), 100, np.uint8)
    a = e.copy()
    a[1, 2] = (100, 100, 200)  # past the threshold
    a[3, 5] = (103, 100, 100)  # within it
    return e, a


def _failed_outcome(texts=None):
    e, a = _pair()
    d = compare_frame(6, e, a, color_threshold=5)
    fr = report.FrameReport(6, d.message(), e, a, d)
    only = report.FrameReport(9, "frame 9: not in the golden", None, a)
    return report.Outcome(
        "demo",
        "scenarios/demo.yaml",
        "collide2d bless scenarios/demo.yaml",
        status=report.STATUS_FAILED,
        problems=["events: first divergence at event #1 (tick 1, wall, 0): side differs", fr, only],
        texts=texts or {},
    )


def test_diff_image_highlights_exactly_the_differing_pixels():
    out = _failed_outcome()
    img = report.diff_image(out.frames[0])
    assert img.shape == (4, 6, 3) and img.dtype == np.uint8
    assert tuple(img[1, 2]) == report.DIFF_COLOR
    assert tuple(img[3, 5]) == report.WITHIN_THRESHOLD_COLOR
    grey = int(100 * report.DIM_LEVEL)
    rest = np.ones((4, 6), bool)
    rest[1, 2] = rest[3, 5] = False
    assert (img[rest] == grey).all()
    assert report.diff_image(out.frames[1]) is None


def test_scenario_report_folder(tmp_path):
    out = _failed_outcome(texts={"events_expected.jsonl": b"{}\n", "events_actual.jsonl": b"\n"})
    index = report.write_scenario(tmp_path, out)
    folder = tmp_path / "demo"
    assert index == folder / "index.html" and out.report == index
    e, a = _pair()
    assert np.array_equal(decode_png((folder / "frame_000006_expected.png").read_bytes()), e)
    assert np.array_equal(decode_png((folder / "frame_000006_actual.png").read_bytes()), a)
    diff = decode_png((folder / "frame_000006_diff.png").read_bytes())
    assert tuple(diff[1, 2]) == report.DIFF_COLOR
    assert sorted(out.frames[1].paths) == ["actual"]  # nothing to compare it with
    assert (folder / "events_expected.jsonl").read_bytes() == b"{}\n"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert summary["frames"][0]["diff"] == "frame_000006_diff.png"
    assert summary["frames"][0]["bbox"] == [2, 1, 2, 1]
    assert summary["problems"][0].startswith("events: first divergence")
    assert summary["bless"] == "collide2d bless scenarios/demo.yaml"


def _assert_self_contained(page, folder):
    assert "http://" not in page and "https://" not in page and "<script" not in page
    srcs = re.findall(r'(?:src|href)="([^"#]+)"', page)
    assert srcs, "the page shows no images"
    for src in srcs:
        assert not src.startswith("/") and ":" not in src
        assert (folder / src).is_file(), src


def test_pages_are_self_contained_with_side_by_side_and_diff_views(tmp_path):
    out = _failed_outcome(texts={"final_expected.csv": b"id,x,y,vx,vy\n"})
    page_path = report.write_scenario(tmp_path, out)
    page = page_path.read_text()
    _assert_self_contained(page, page_path.parent)
    assert "side by side" in page and ">diff<" in page
    # frame 6: expected, actual, diff side by side and the diff alone; frame 9: its run frame
    assert page.count("<img") == 5
    assert "No diff image" in page
    ok = report.Outcome("zeta", "scenarios/zeta.yaml", "collide2d bless scenarios/zeta.yaml")
    index = report.write_index(tmp_path, [ok, out], unused=["old"])
    top = index.read_text()
    _assert_self_contained(top, tmp_path)
    assert 'src="demo/frame_000006_diff.png"' in top
    assert "old" in top and "collide2d bless --prune" in top
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (summary["passed"], summary["failed"]) == (1, 1)
    assert [s["name"] for s in summary["scenarios"]] == ["demo", "zeta"]
    assert summary["unused_goldens"] == ["old"]
    assert summary["scenarios"][0]["frames"][0]["diff"] == "demo/frame_000006_diff.png"


def test_html_escapes_what_it_shows(tmp_path):
    out = _failed_outcome()
    out.problems[0] = "events: <b>&"
    page = report.write_scenario(tmp_path, out).read_text()
    assert "<b>&" not in page and "&lt;b&gt;&amp;" in page


def test_message_lists_problems_paths_and_command(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    out = _failed_outcome()
    lines = out.message().splitlines()
    assert lines[0] == "FAILED  demo (scenarios/demo.yaml)"
    assert "  (pass --report DIR for expected / actual / diff images)" in lines
    report.write_scenario(tmp_path / "rep", out)
    msg = out.message()
    assert "    expected: rep/demo/frame_000006_expected.png" in msg
    assert "    diff:     rep/demo/frame_000006_diff.png" in msg
    assert "  report: rep/demo/index.html" in msg
    assert msg.index("events:") < msg.index("frame 6") < msg.index("frame 9")
