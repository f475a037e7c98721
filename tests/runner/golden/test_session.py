"""Tests of runner/golden/session.py: checking a run against its golden, and blessing it."""

from __future__ import annotations

import json

import pytest

from collide2d.runner.golden import CREATED, UNCHANGED, UPDATED, bless_run, check_run, serialize
from collide2d.runner.golden.store import GoldenStore

from . import synthetic


def _scn(tree, **changes):
    path = synthetic.write(tree / "scenarios" / "demo.yaml", synthetic.spec(**changes))
    scn = synthetic.load(path)
    return scn, synthetic.simulate(scn, keep_frames=scn.golden.frames)


def _blessed(tree, **changes):
    scn, run = _scn(tree, **changes)
    store = GoldenStore(tree)
    assert bless_run(scn, run, store).status == CREATED
    return store


def _check(tree, store, report_dir=None, **changes):
    scn, run = _scn(tree, **changes)
    return check_run(scn, run, store, report_dir=report_dir)


def test_an_identical_run_passes(tree):
    store = _blessed(tree)
    out = _check(tree, store)
    assert out.ok and out.problems == []
    assert out.message() == "ok      demo"


def _pixels(*extra):
    return synthetic.BASE["pixels"] + list(extra)


def test_a_changed_pixel_fails_naming_frame_count_box_and_command(tree):
    store = _blessed(tree)
    out = _check(tree, store, pixels=_pixels([4, 6, 1, 0, 0, 9]))
    assert out.status == "failed"
    msg = out.message()
    assert msg.splitlines()[0] == "FAILED  demo (scenarios/demo.yaml)"
    assert "frame 4: 1 pixel(s) differ (colour threshold 0, budget 0) within x 6..6, y 1..1" in msg
    assert "frame 0" not in msg
    assert msg.splitlines()[-1] == (
        "  to accept this run as the golden: collide2d bless scenarios/demo.yaml"
    )


def test_pixel_tolerances_come_from_the_scenario(tree):
    store = _blessed(tree)
    loose = {**synthetic.BASE["golden"], "max_diff_pixels": 1, "color_threshold": 8}
    changed = _pixels([4, 6, 1, 0, 0, 9], [4, 0, 0, 8, 8, 8])
    assert _check(tree, store, golden=loose, pixels=changed).ok
    assert not _check(tree, store, golden=loose, pixels=changed + [[4, 7, 5, 0, 99, 0]]).ok


def test_a_changed_event_fails_at_its_index(tree):
    store = _blessed(tree)
    events = [[2, 0.2, 0, 1, -1, 0, -1, -1], [3, 0.3, 1, 0, 1, 1, 2, 5]]
    msg = _check(tree, store, events=events).message()
    assert "events: first divergence at event #2 (tick 3, pair, 0-1): axis differs" in msg
    assert '"axis": "x"' in msg and '"axis": "y"' in msg


def test_event_time_past_tolerance_fails_and_within_passes(tree):
    store = _blessed(tree)
    later = [[2, 0.2, 0, 1, -1, 0, -1, -1], [3, 0.3 + 1e-6, 1, 0, 1, 0, 2, 5]]
    msg = _check(tree, store, events=later).message()
    assert "event #2 (tick 3, pair, 0-1): t differs by 1e-06 s, past time_tolerance 0 s" in msg
    tol = {**synthetic.BASE["golden"], "time_tolerance": 2e-6}
    assert _check(tree, store, events=later, golden=tol).ok


def test_a_changed_final_state_fails(tree):
    store = _blessed(tree)
    out = _check(tree, store, final=[[1.0, 2.0, 10.0, 0.0], [5.5, 3.5, -10.0, 2.5]])
    assert not out.ok
    assert "final state: 1 value(s) past tolerance, first object 1 y: expected 3.0" in out.message()
    assert "events" not in out.message() and "frame" not in out.message()


def test_a_frame_of_another_size_fails_on_its_own(tree):
    store = _blessed(tree)
    msg = _check(tree, store, sizes={"4": [9, 6]}).message()
    assert "frame 4: size differs: golden 8x6, run 9x6" in msg


def test_golden_frames_added_or_dropped_fail(tree):
    store = _blessed(tree)
    more = {**synthetic.BASE["golden"], "frames": [0, 2, 4]}
    assert (
        "frame 2: not in the golden (its frames are [0, 4])"
        in _check(tree, store, golden=more).message()
    )
    fewer = {**synthetic.BASE["golden"], "frames": [0]}
    assert (
        "frame 4: in the golden, but no longer among" in _check(tree, store, golden=fewer).message()
    )


def test_a_missing_golden_fails_and_names_the_command(tree):
    out = _check(tree, GoldenStore(tree))
    assert out.status == "missing"
    msg = out.message()
    assert "no golden for demo" in msg
    assert msg.splitlines()[-1] == "  to create it: collide2d bless scenarios/demo.yaml"
    assert not (tree / "goldens").exists()


def test_an_unreadable_golden_fails(tree):
    store = _blessed(tree)
    (store.folder("demo") / serialize.FINAL_FILE).write_text("id,x,y,vx,vy\n")
    out = _check(tree, store)
    assert out.status == "unreadable"
    assert "final.csv does not match manifest.json" in out.message()


def test_report_files_are_named_in_the_message(tree):
    store = _blessed(tree)
    report = tree / "report"
    out = _check(tree, store, report_dir=report, pixels=_pixels([4, 6, 1, 0, 0, 9]))
    msg = out.message()
    for kind in ("expected", "actual", "diff"):
        path = report / "demo" / f"frame_000004_{kind}.png"
        assert path.is_file()
        assert f"{kind}:" in msg and f"report/demo/frame_000004_{kind}.png" in msg
    assert "report: report/demo/index.html" in msg
    summary = json.loads((report / "demo" / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["frames"][0]["n_diff"] == 1


def test_bless_created_updated_unchanged(tree):
    scn, run = _scn(tree)
    store = GoldenStore(tree)
    first = bless_run(scn, run, store)
    assert (first.status, first.summary) == (CREATED, "2 events, 2 frames, 2 objects")
    again = bless_run(scn, run, store)
    assert (again.status, again.files) == (UNCHANGED, ())
    assert again.line() == "unchanged demo: no change"
    scn, run = _scn(
        tree,
        pixels=_pixels([4, 6, 1, 0, 0, 9], [4, 7, 1, 0, 0, 9]),
        final=[[1.0, 2.0, 10.0, 0.0], [5.5, 3.5, -10.0, 2.5]],
    )
    third = bless_run(scn, run, store)
    assert third.status == UPDATED
    assert third.summary == "frames 4 (2 px); final state (1 values)"
    assert third.files == ("final.csv", "frames/frame_000004.png", "manifest.json")
    assert check_run(scn, run, store).ok


def test_bless_names_changed_events(tree):
    store = _blessed(tree)
    scn, run = _scn(tree, events=[[2, 0.2, 0, 1, -1, 0, -1, -1]])
    out = bless_run(scn, run, store)
    assert out.summary == "events from #2 (tick 3, pair, 0-1; 2 -> 1 events)"


def test_reblessing_reproduces_every_byte(tree):
    store = _blessed(tree)
    before = {p: p.read_bytes() for p in sorted(store.folder("demo").rglob("*")) if p.is_file()}
    for p in before:
        p.unlink()
    scn, run = _scn(tree)
    assert bless_run(scn, run, store).status == CREATED
    after = {p: p.read_bytes() for p in sorted(store.folder("demo").rglob("*")) if p.is_file()}
    assert after == before


def test_bless_keeps_png_bytes_when_pixels_are_the_same(tree):
    store = _blessed(tree)
    png = store.folder("demo") / serialize.frame_file(4)
    from PIL import Image

    with Image.open(png) as im:
        im.load()
        im.save(png, format="PNG", compress_level=1)  # another encoder's bytes, same pixels
    other = png.read_bytes()
    scn, run = _scn(tree)
    assert bless_run(scn, run, store).status == UNCHANGED
    assert png.read_bytes() == other


@pytest.mark.parametrize("garbage", [b"{", b"[]"])
def test_bless_replaces_an_unreadable_golden(tree, garbage):
    store = _blessed(tree)
    (store.folder("demo") / serialize.MANIFEST_FILE).write_bytes(garbage)
    scn, run = _scn(tree)
    out = bless_run(scn, run, store)
    assert out.status == UPDATED and out.summary.startswith("replaced an unreadable golden")
    assert check_run(scn, run, store).ok


def test_a_failure_notes_settings_changed_since_the_bless(tree):
    store = _blessed(tree)
    assert _check(tree, store, ticks=5).ok  # same results: the settings alone are no failure
    out = _check(tree, store, ticks=5, final=[[1.0, 2.0, 10.0, 0.0], [6.5, 3.0, -10.0, 2.5]])
    assert out.problems[0] == "note: the golden was blessed with ticks 4, the scenario now has 5"
    assert len(out.problems) == 2 and out.problems[1].startswith("final state:")


def test_a_created_summary_counts_in_words(tree):
    scn, run = _scn(tree, events=[[2, 0.2, 0, 1, -1, 0, -1, -1]], final=[[1.0, 2.0, 3.0, 4.0]])
    assert bless_run(scn, run, GoldenStore(tree)).summary == "1 event, 2 frames, 1 object"
