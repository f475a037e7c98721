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
    slider.fill("0")
    assert np.array_equal(shot(stack), run)
    slider.fill("100")
    assert np.array_equal(shot(stack), golden)
    slider.fill("50")
    half = shot(stack)
    w = half.shape[1] // 2
    assert np.array_equal(half[:, :w], golden[:, :w]) and np.array_equal(half[:, w:], run[:, w:])
    frame.locator(".msg").click()  # the keys act on the current frame, not the focused slider
    page.keyboard.press("ArrowLeft")  # the handle to 40 %: more of the run shows
    assert slider.input_value() == "40"
    fewer = shot(stack)
    w = fewer.shape[1] * 4 // 10
    assert np.array_equal(fewer[:, :w], golden[:, :w]) and np.array_equal(fewer[:, w:], run[:, w:])
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
