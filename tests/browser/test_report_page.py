"""The report page in Chromium: summary line, failures first, the filter, blink, slider and the
keys, on a real check of Figure 2's scenarios where one box moved by 2 px and another started
faster (their goldens copied from goldens/)."""

from __future__ import annotations

import base64
import io
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from collide2d.runner.golden import cli

from .conftest import save_screenshot, shot

ROOT = Path(__file__).resolve().parents[2]
EDITS = {
    "fig2_case1": ("position: [100, 100]", "position: [102, 100]"),
    "fig2_case3": ("velocity: [10, 10]", "velocity: [20, 10]"),
    "fig2_case2": None,
}


@pytest.fixture(scope="module")
def report_page(tmp_path_factory):
    """rep/index.html of `collide2d check --report rep` over the three scenarios."""
    tree = tmp_path_factory.mktemp("review")
    (tree / "scenarios").mkdir()
    for name, edit in EDITS.items():
        text = (ROOT / "scenarios" / f"{name}.yaml").read_text()
        if edit is not None:
            assert edit[0] in text
            text = text.replace(edit[0], edit[1], 1)
        (tree / "scenarios" / f"{name}.yaml").write_text(text)
        shutil.copytree(ROOT / "goldens" / name, tree / "goldens" / name)
    status = cli.main(["check", "--quiet", "--root", str(tree), "--report", str(tree / "rep")])
    assert status == 1
    return (tree / "rep" / "index.html").as_uri()


def _data_image(img) -> np.ndarray:
    src = img.get_attribute("src")
    data = base64.b64decode(src.split(",", 1)[1])
    return np.array(Image.open(io.BytesIO(data)).convert("RGB"))


def test_summary_failures_first_and_the_filter(clean_page, report_page):
    page = clean_page
    page.goto(report_page)
    assert page.locator("#summary").inner_text() == "2 failed, 1 passed"
    sections = page.locator("section.scenario")
    assert [sections.nth(i).get_attribute("id") for i in range(3)] == [
        "sc-fig2_case1",
        "sc-fig2_case3",
        "sc-fig2_case2",
    ]
    why = page.locator("#sc-fig2_case1 .why")
    assert "the scenario was edited since bless" in why.inner_text()
    assert page.locator("#sc-fig2_case1 table.events tr.first").count() == 1
    assert page.locator("#sc-fig2_case2").is_visible()
    page.locator("#only-failures").check()
    assert page.locator("#sc-fig2_case2").is_hidden()
    assert page.locator("#sc-fig2_case1").is_visible()
    page.keyboard.press("f")
    assert page.locator("#sc-fig2_case2").is_visible()
    page.locator("#only-failures").check()
    bottom = page.locator("#sc-fig2_case1 .frame .caption").first.bounding_box()
    height = int(bottom["y"] + bottom["height"]) + 8
    save_screenshot(page, "report.png", clip={"x": 0, "y": 0, "width": 1000, "height": height})


DIVIDER = [(9, 105, 218), (255, 255, 255), (9, 105, 218)]  # the slider's divider, 3 px


def _split_at(got, golden, run, w):
    """The slider's picture with its handle at column w: the golden left of w, the run from w
    on, and the divider (blue, white, blue) over columns w-1..w+1, top to bottom."""
    cols = [c for c in (w - 1, w, w + 1) if 0 <= c < got.shape[1]]
    for c in cols:
        assert (got[:, c] == DIVIDER[c - w + 1]).all(), (w, c)
    left, right = max(0, w - 1), w + 2
    assert np.array_equal(got[:, :left], golden[:, :left])
    assert np.array_equal(got[:, right:], run[:, right:])


def test_blink_and_slider_change_the_image_shown(clean_page, report_page):
    page = clean_page
    page.goto(report_page)
    frame = page.locator("#sc-fig2_case1 .frame").first
    golden = _data_image(frame.locator(".stack img.under"))
    run = _data_image(frame.locator(".stack img.over"))
    assert not np.array_equal(golden, run)
    stack = frame.locator(".stack")
    frame.locator('button[data-view="blink"]').click()
    assert np.array_equal(shot(stack), golden)
    page.keyboard.press("b")  # toggle
    assert np.array_equal(shot(stack), run)
    page.keyboard.press("b")
    assert np.array_equal(shot(stack), golden)
    frame.locator('button[data-view="slider"]').click()
    slider = frame.locator('input[type="range"]')
    for value, w in (("0", 0), ("100", golden.shape[1]), ("50", golden.shape[1] // 2)):
        slider.fill(value)
        _split_at(shot(stack), golden, run, w)
    frame.locator(".msg").click()  # the keys act on the current frame, not the focused slider
    page.keyboard.press("ArrowLeft")  # the handle to 40 %: more of the run shows
    assert slider.input_value() == "40"
    _split_at(shot(stack), golden, run, golden.shape[1] * 4 // 10)
    frame.locator('button[data-view="diff"]').click()
    assert frame.locator(".panel.diff img").is_visible() and stack.is_hidden()


def test_keys_step_through_frames_and_failures(clean_page, report_page):
    page = clean_page
    page.goto(report_page)
    frames = page.locator(".frame")
    assert frames.count() >= 3
    page.keyboard.press("j")
    assert "current" in frames.nth(0).get_attribute("class")
    page.keyboard.press("j")
    assert "current" in frames.nth(1).get_attribute("class")
    assert "current" not in frames.nth(0).get_attribute("class")
    page.keyboard.press("k")
    assert "current" in frames.nth(0).get_attribute("class")
    page.keyboard.press("4")
    assert frames.nth(0).get_attribute("data-view") == "diff"
    page.keyboard.press("n")
    assert page.evaluate("location.hash") == "#sc-fig2_case3"
    current = page.locator(".frame.current")
    assert current.count() == 1
    assert current.evaluate("f => f.closest('section').id") == "sc-fig2_case3"
    page.keyboard.press("p")
    assert page.evaluate("location.hash") == "#sc-fig2_case1"


BOUNCER = """version: 1
world: {width: 40, height: 20, fps: 30}
ticks: 60
objects:
  - {name: runner, shape: box, size: 4, position: [2, 2], velocity: [300, 0]}
"""
SINKER = "  - {name: sinker, shape: box, size: 4, position: [20, 10], velocity: [0, 6]}\n"


@pytest.fixture(scope="module")
def bouncer_report(tmp_path_factory):
    """rep/bouncer/ of a check where an object was added after bless: its one wall event is
    inserted in the middle of the other's 15."""
    tree = tmp_path_factory.mktemp("bouncer")
    (tree / "scenarios").mkdir()
    (tree / "scenarios" / "bouncer.yaml").write_text(BOUNCER)
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("CI", raising=False)  # bless writes goldens, which CI never does
        assert cli.main(["bless", "--quiet", "--root", str(tree)]) == 0
    (tree / "scenarios" / "bouncer.yaml").write_text(BOUNCER + SINKER)
    status = cli.main(["check", "--quiet", "--root", str(tree), "--report", str(tree / "rep")])
    assert status == 1
    return tree / "rep" / "bouncer"


def test_folded_events_expand_and_fold_again(clean_page, bouncer_report):
    page = clean_page
    page.goto((bouncer_report / "index.html").as_uri())
    table = page.locator("table.events")
    inserted = table.locator("tr.first")
    assert "sinker (#1)" in inserted.inner_text()  # the inserted event shifts nothing after it
    assert table.locator("tr.changed, tr.dropped, tr.inserted").count() == 0
    button = table.locator("button.unfold").first
    n = int(button.inner_text().split()[1])  # "… N matching events before (show)"
    rows = table.locator("tr.folded")
    assert rows.count() >= n > 0 and rows.first.is_hidden()
    shown = table.locator("tr:visible").count()
    button.click()
    assert table.locator("tr:visible").count() == shown + n and rows.first.is_visible()
    assert button.inner_text().endswith("(hide)")
    button.click()
    assert table.locator("tr:visible").count() == shown and rows.first.is_hidden()


def test_the_reports_viewer_shows_the_golden_as_a_ghost(clean_page, bouncer_report):
    page = clean_page
    page.goto((bouncer_report / "viewer.html").as_uri())
    page.wait_for_selector("body[data-ready='1']")
    page.select_option("#zoom", "1")
    canvas = page.locator("#view")
    png = lambda kind: np.array(  # noqa: E731
        Image.open(bouncer_report / f"frame_000030_{kind}.png").convert("RGB")
    )
    run, golden = png("actual"), png("expected")
    differ = (run != golden).any(axis=2)
    assert differ.any()
    page.locator("button.ghost-frame", has_text="30").click()
    assert page.locator("#view").get_attribute("data-tick") == "30"
    assert page.locator("#ov-ghost").is_checked()
    got = shot(canvas)
    assert np.array_equal(got[~differ], run[~differ])
    mean = ((run.astype(int) + golden) >> 1).astype(np.uint8)
    assert np.array_equal(got[differ], mean[differ])
    page.locator("#ov-ghost").uncheck()
    assert np.array_equal(shot(canvas), run)
    page.keyboard.press("ArrowRight")  # no golden frame at 31: the run alone
    assert page.locator("#view").get_attribute("data-tick") == "31"
    alone = shot(canvas)
    page.locator("#ov-ghost").check()
    assert np.array_equal(shot(canvas), alone)
