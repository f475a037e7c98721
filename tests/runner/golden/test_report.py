"""Tests of runner/golden/report.py and page.py: diff images, report folders, whole pages."""

from __future__ import annotations

import base64
import html
import json
import os
import re
import shutil
from pathlib import Path
from urllib.parse import unquote_to_bytes

import numpy as np

from collide2d.runner.golden import page as golden_page
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
    img = golden_page.diff_image(out.frames[0])
    assert img.shape == (4, 6, 3) and img.dtype == np.uint8
    assert tuple(img[1, 2]) == golden_page.DIFF_COLOR
    assert tuple(img[3, 5]) == golden_page.WITHIN_THRESHOLD_COLOR
    grey = int(100 * golden_page.DIM_LEVEL)
    rest = np.ones((4, 6), bool)
    rest[1, 2] = rest[3, 5] = False
    assert (img[rest] == grey).all()
    assert golden_page.diff_image(out.frames[1]) is None


def test_scenario_report_folder(tmp_path):
    out = _failed_outcome(texts={"events_expected.jsonl": b"{}\n", "events_actual.jsonl": b"\n"})
    index = report.write_scenario(tmp_path, out)
    folder = tmp_path / "demo"
    assert index == folder / "index.html" and out.report == index
    e, a = _pair()
    assert np.array_equal(decode_png((folder / "frame_000006_expected.png").read_bytes()), e)
    assert np.array_equal(decode_png((folder / "frame_000006_actual.png").read_bytes()), a)
    diff = decode_png((folder / "frame_000006_diff.png").read_bytes())
    assert tuple(diff[1, 2]) == golden_page.DIFF_COLOR
    assert sorted(out.frames[1].paths) == ["actual"]  # nothing to compare it with
    assert (folder / "events_expected.jsonl").read_bytes() == b"{}\n"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert summary["frames"][0]["diff"] == "frame_000006_diff.png"
    assert summary["frames"][0]["bbox"] == [2, 1, 2, 1]
    assert summary["problems"][0].startswith("events: first divergence")
    assert summary["bless"] == "collide2d bless scenarios/demo.yaml"


def _links(page_path) -> list:
    """The files a page links, as paths: every href is an anchor or a relative link to a file
    that exists in the report folder."""
    page = page_path.read_text()
    out = []
    for href in re.findall(r'href="([^"]+)"', page):
        if href.startswith("#"):
            continue
        href = html.unescape(href)
        assert ":" not in href and not href.startswith("/"), href
        target = (page_path.parent / os.fsdecode(unquote_to_bytes(href))).resolve()
        assert target.is_file(), href
        out.append(target)
    return out


def _assert_self_contained(page):
    """Nothing is loaded from anywhere: every src is an inline image, every href an anchor or a
    relative link (to a file beside the page, `_links`)."""
    assert "http://" not in page and "https://" not in page and "<link" not in page
    srcs = re.findall(r'src="([^"]+)"', page)
    assert srcs, "the page shows no images"
    assert all(src.startswith("data:image/png;base64,") for src in srcs)
    assert all(":" not in h for h in re.findall(r'href="([^"]+)"', page))


def _images(page) -> list[np.ndarray]:
    return [
        decode_png(base64.b64decode(src))
        for src in re.findall(r'src="data:image/png;base64,([^"]+)"', page)
    ]


def test_pages_are_self_contained_with_crops_views_and_full_frames(tmp_path):
    out = _failed_outcome(texts={"final_expected.csv": b"id,x,y,vx,vy\n"})
    page_path = report.write_scenario(tmp_path, out)
    page = page_path.read_text()
    _assert_self_contained(page)
    for view in ("side by side", "blink", "slider", "diff"):
        assert f">{view}</button>" in page
    e, a = _pair()
    images = _images(page)
    # frame 6: the crop (the whole 6x4 frame: smaller than the least crop) enlarged 40x as
    # golden, run and diff side by side, golden and run stacked for blink and slider, the diff
    # alone, then the full run frame; frame 9: its run frame only
    zoom = golden_page.crop_zoom((0, 0, 6, 4))
    assert zoom == 16  # CROP_TARGET // 6 = 40, at most CROP_MAX_ZOOM
    big = lambda rgb: rgb.repeat(zoom, axis=0).repeat(zoom, axis=1)  # noqa: E731
    diff = golden_page.diff_image(out.frames[0])
    expected = [big(e), big(a), big(diff), big(e), big(a), big(diff), a, a]
    assert len(images) == len(expected)
    for got, want in zip(images, expected, strict=True):
        assert np.array_equal(got, want)
    ok = report.Outcome("alpha", "scenarios/alpha.yaml", "collide2d bless scenarios/alpha.yaml")
    index = report.write_index(tmp_path, [ok, out], unused=["old"])
    top = index.read_text()
    _assert_self_contained(top)
    assert '<p id="summary" class="summary bad">1 failed, 1 passed</p>' in top
    assert top.index('id="sc-demo"') < top.index('id="sc-alpha"')  # failures first
    assert "old" in top and "collide2d bless --prune" in top
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (summary["passed"], summary["failed"]) == (1, 1)
    assert summary["summary"] == "1 failed, 1 passed"
    assert [s["name"] for s in summary["scenarios"]] == ["alpha", "demo"]
    assert summary["unused_goldens"] == ["old"]
    assert summary["scenarios"][1]["frames"][0]["diff"] == "demo/frame_000006_diff.png"


def test_crop_surrounds_the_change_within_the_frame():
    # a 3x2 change near the right edge of a 320x240 frame
    box = golden_page.crop_box((315, 100, 317, 101), 320, 240)
    x0, y0, x1, y1 = box
    assert x1 == 320 and x1 - x0 == golden_page.CROP_MIN  # pushed back inside, at least CROP_MIN
    assert y0 <= 100 - golden_page.CROP_MARGIN and y1 >= 102 + golden_page.CROP_MARGIN
    assert y1 - y0 == golden_page.CROP_MIN
    # a large change keeps its margin
    assert golden_page.crop_box((10, 20, 109, 59), 320, 240) == (4, 14, 116, 66)
    assert golden_page.crop_zoom((4, 14, 116, 66)) == 2


def _event_rows(out) -> list:
    """(kind, golden #, run #, golden cell, run cell) of each row of the page's event table."""
    page = golden_page.page("t", [out]).decode()
    table = page[page.index('<table class="events">') : page.index("</table>")]
    rows = re.findall(
        r'<tr class="(\w+)[^"]*"(?: hidden)?><td>(\d*)</td><td>(.*?)</td><td>(\d*)</td>'
        r"<td>(.*?)</td></tr>",
        table,
    )
    return [(k, int(i) if i else None, int(j) if j else None, e, a) for k, i, e, j, a in rows]


def test_event_diff_aligns_the_logs_and_names_the_objects():
    """An event the run inserted or dropped shifts nothing after it: every other event stands
    beside its equal; objects are named by their `name` (with their id), or by id alone."""

    def line(tick, i, side="left"):
        return {"tick": tick, "t": tick / 10, "type": "wall", "id": i, "side": side}

    golden = [line(k, k % 3) for k in range(20)]
    run = golden[:4] + [line(4, 2, "top")] + golden[4:12] + golden[13:16]
    run += [line(16, 0, "right")] + golden[17:]  # inserted after #4, #13 dropped, #17 changed
    out = _failed_outcome(
        texts={
            name: "".join(json.dumps(e) + "\n" for e in events).encode()
            for name, events in (("events_expected.jsonl", golden), ("events_actual.jsonl", run))
        }
    )
    out.first_event, out.names = 4, ("box", None, "<b>ball</b>")
    rows = _event_rows(out)
    kinds = {(k, i, j) for k, i, j, _e, _a in rows if k not in ("same", "folded")}
    assert kinds == {("first", None, 5), ("dropped", 13, None), ("changed", 17, 17)}
    for kind, i, j, e, a in rows:
        if kind == "same":  # every matching event beside its equal, whatever came before
            assert e == a and golden[i - 1] == run[j - 1]
    # all 20 golden events shown (folded or not), in order
    assert [i for _k, i, _j, _e, _a in rows if i is not None] == list(range(1, 21))
    first = next(r for r in rows if r[0] == "first")
    assert first[4].startswith("tick 4, wall, &lt;b&gt;ball&lt;/b&gt; (#2) ")
    dropped = next(r for r in rows if r[0] == "dropped")
    assert dropped[3].startswith("tick 12, wall, box (#0) ") and dropped[4] == "<i>(none)</i>"
    assert next(r for r in rows if r[1] == 2)[3].startswith("tick 1, wall, #1 ")


def test_html_escapes_what_it_shows(tmp_path):
    out = _failed_outcome()
    out.problems[0] = "events: <b>&"
    page = report.write_scenario(tmp_path, out).read_text()
    assert "<b>&" not in page and "&lt;b&gt;&amp;" in page


def test_a_file_name_of_any_bytes_shows_on_the_page(tmp_path):
    """Found by hardening: a scenario file name holding a byte that is not UTF-8 (or a control
    character) made writing the report page a crash, exit 3."""
    scenario = os.fsdecode(b"scenarios/d\x1b[2J\xffemo.yaml")
    out = _failed_outcome()
    out.scenario, out.bless = scenario, f"collide2d bless {scenario}"
    out.problems[0] = "events: type differs (golden pa\x1b[2Jir\x00)"
    page = report.write_scenario(tmp_path, out).read_text()
    assert "<code>scenarios/d\\x1b[2J\\xffemo.yaml</code>" in page
    assert "golden pa\\x1b[2Jir\\x00" in page and "\x1b" not in page


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


def _moved_box_report(tmp_path) -> Path:
    """rep/ of `collide2d check --report rep` where one box of fig2_case1 starts 2 px right."""
    from collide2d.runner.golden import cli

    root = Path(__file__).resolve().parents[3]
    (tmp_path / "scenarios").mkdir()
    text = (root / "scenarios" / "fig2_case1.yaml").read_text()
    assert "position: [100, 100]" in text
    text = text.replace("position: [100, 100]", "position: [102, 100]", 1)
    (tmp_path / "scenarios" / "fig2_case1.yaml").write_text(text)
    shutil.copytree(root / "goldens" / "fig2_case1", tmp_path / "goldens" / "fig2_case1")
    argv = ["check", "--quiet", "--root", str(tmp_path), "--report", str(tmp_path / "rep")]
    assert cli.main(argv) == 1
    return tmp_path / "rep"


def test_the_report_links_the_full_logs_both_full_frames_and_a_viewer(tmp_path):
    rep = _moved_box_report(tmp_path)
    folder = rep / "fig2_case1"
    for page_path in (rep / "index.html", folder / "index.html"):
        linked = {p.relative_to(folder.resolve()).as_posix() for p in _links(page_path)}
        frames = {p.name for p in folder.glob("frame_*.png")}
        assert {n[: -len("_actual.png")] for n in frames if n.endswith("_actual.png")}
        texts = {p.name for p in folder.iterdir() if p.suffix in (".jsonl", ".csv")}
        assert {"events_expected.jsonl", "events_actual.jsonl"} <= texts
        assert linked == frames | texts | {"viewer.html"}, page_path
    assert b'id="data"' in (folder / "viewer.html").read_bytes()


def test_a_failing_checks_viewer_holds_the_golden_frames_as_its_ghost(tmp_path):
    import zlib

    from collide2d.runner.golden.store import GoldenStore

    rep = _moved_box_report(tmp_path)
    page = (rep / "fig2_case1" / "viewer.html").read_text()
    head = '<script id="data" type="application/json">'
    data = json.loads(page[page.index(head) + len(head) :].split("</script>", 1)[0])
    golden = GoldenStore(tmp_path).read("fig2_case1")
    assert data["ghostFrames"] == sorted(golden.frames) and len(golden.frames) > 1
    ghost = np.frombuffer(zlib.decompress(base64.b64decode(data["ghost"])), np.uint8)
    h, w = data["height"], data["width"]
    ghost = ghost.reshape(len(data["ghostFrames"]), h, w, 3)
    for k, rgb in zip(data["ghostFrames"], ghost, strict=True):
        assert np.array_equal(rgb, golden.frames[k]), k
    assert data["frames"] == 21 and data["overlay"] == ["overlap"]  # this run, as it asks
    assert 'id="ov-ghost" checked' in page
