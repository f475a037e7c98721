"""The run viewer in Chromium: it draws the PNG frames' very pixels at zoom 1 (and their enlarged
pixels at zoom 2), plays, steps, seeks to an event's tick and outlines the pair, names objects on
hover with their position and velocity, and its overlays draw over the frame; on a run of the
shapes showcase (boxes, circles of odd and even diameter, polygons, fills) under the `exact`
model, whose positions are fractional."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from collide2d.engine.picture.raster import round_positions
from collide2d.runner.command import main
from collide2d.runner.run import drive
from collide2d.runner.scenario.load import load

from .conftest import save_screenshot, shot

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def viewer_run(tmp_path_factory):
    """(run folder, viewer URL) of the showcase run with every PNG frame and the viewer."""
    tmp = tmp_path_factory.mktemp("viewer")
    text = (ROOT / "scenarios" / "shapes_showcase.yaml").read_text()
    text = text.replace("output: {frames: {every: 10}", "output: {frames: all")
    (tmp / "showcase.yaml").write_text(text)
    argv = ["run", str(tmp / "showcase.yaml"), "--out", str(tmp / "out"), "--model", "exact"]
    assert main.main([*argv, "--viewer", "--png", "--no-gif", "--quiet"]) == 0
    folder = tmp / "out" / "showcase"
    return folder, (folder / "viewer.html").as_uri()


def _open(page, url, zoom=1):
    page.goto(url)
    page.wait_for_selector("body[data-ready='1']")
    page.select_option("#zoom", str(zoom))
    return page.locator("#view")


def _tick(page) -> int:
    return int(page.locator("#view").get_attribute("data-tick"))


def _png(folder, k) -> np.ndarray:
    return np.array(Image.open(folder / "frames" / f"frame_{k:06d}.png").convert("RGB"))


def test_canvas_draws_the_png_frame_at_every_tick_shown(clean_page, viewer_run):
    folder, url = viewer_run
    canvas = _open(clean_page, url)
    for k in (0, 7, 23, 41, 60):
        clean_page.locator("#seek").fill(str(k))
        assert _tick(clean_page) == k
        assert np.array_equal(shot(canvas), _png(folder, k)), f"tick {k}"
    clean_page.select_option("#zoom", "2")
    big = _png(folder, 60).repeat(2, axis=0).repeat(2, axis=1)
    assert np.array_equal(shot(canvas), big)


def test_play_pause_and_single_steps(clean_page, viewer_run):
    _folder, url = viewer_run
    _open(clean_page, url)
    clean_page.select_option("#speed", "8")
    clean_page.locator("#play").click()
    clean_page.wait_for_function("Number(document.getElementById('view').dataset.tick) >= 5")
    clean_page.keyboard.press(" ")  # pause
    assert clean_page.locator("body").get_attribute("data-playing") == "0"
    k = _tick(clean_page)
    clean_page.keyboard.press("ArrowRight")
    assert _tick(clean_page) == k + 1
    clean_page.keyboard.press("ArrowLeft")
    clean_page.keyboard.press("ArrowLeft")
    assert _tick(clean_page) == k - 1
    clean_page.locator("#fwd").click()
    assert _tick(clean_page) == k
    clean_page.keyboard.press("End")
    assert _tick(clean_page) == 60
    assert "tick 60 / 60" in clean_page.locator("#tick").inner_text()


def test_clicking_an_event_seeks_to_its_tick_and_outlines_the_pair(clean_page, viewer_run):
    folder, url = viewer_run
    canvas = _open(clean_page, url)
    pair = clean_page.locator("#events li", has_text="pair").first
    tick = int(pair.get_attribute("data-tick"))
    assert tick > 0
    pair.click()
    assert _tick(clean_page) == tick
    assert "selected" in pair.get_attribute("class") and "now" in pair.get_attribute("class")
    got, png = shot(canvas), _png(folder, tick)
    changed = (got != png).any(axis=2)
    assert changed.any()
    assert (got[changed] == (255, 0, 255)).all(axis=1).all()  # only the outline, in magenta


def _state(model, i):
    return round_positions(model.positions())[i], model.velocities()[i]


def _js_number(v) -> str:
    """A velocity as the viewer writes it: rounded to 2 decimals, no trailing `.0`."""
    text = repr(round(float(v), 2))
    return text[:-2] if text.endswith(".0") else text


def test_hover_names_the_object_and_shows_its_position_and_velocity(clean_page, viewer_run):
    _folder, url = viewer_run
    canvas = _open(clean_page, url)
    box = canvas.bounding_box()
    state = clean_page.locator("#hover-state")
    # the static post: 6x30 px at (150, 100), never moves
    clean_page.mouse.move(box["x"] + 152.5, box["y"] + 115.5)
    assert clean_page.locator("#hover").inner_text() == "post (object 6, static)"
    assert state.inner_text() == "at (150, 100) px, velocity (0, 0) px/s"
    # the orange box: 24x16 px at (10, 10), moving at (10, 5) px/s
    clean_page.mouse.move(box["x"] + 20.5, box["y"] + 15.5)
    assert clean_page.locator("#hover").inner_text() == "box (object 0)"
    assert state.inner_text() == "at (10, 10) px, velocity (10, 5) px/s"
    # stepping on follows the object: its recorded position and velocity at that frame
    scn = load(ROOT / "scenarios" / "shapes_showcase.yaml", overrides={"model": "exact"})
    seen = []
    drive(scn, on_tick=lambda m: seen.append(_state(m, 0)))
    clean_page.keyboard.press("ArrowRight")
    clean_page.keyboard.press("ArrowRight")
    (x, y), (vx, vy) = seen[2]
    shown = f"at ({x}, {y}) px, velocity ({_js_number(vx)}, {_js_number(vy)}) px/s"
    assert (x, y) != (10, 10) and state.inner_text() == shown
    clean_page.mouse.move(box["x"] + 2.5, box["y"] + 140.5)
    assert clean_page.locator("#hover").inner_text() == "—" and state.inner_text() == ""


def test_overlays_draw_over_the_frame_and_go_away(clean_page, viewer_run):
    folder, url = viewer_run
    canvas = _open(clean_page, url)
    png = _png(folder, 0)
    for key in ("velocity", "boxes", "labels"):
        clean_page.locator(f"#ov-{key}").check()
        assert not np.array_equal(shot(canvas), png), key
        clean_page.locator(f"#ov-{key}").uncheck()
        assert np.array_equal(shot(canvas), png), key
    pair = clean_page.locator("#events li", has_text="pair").first
    tick = int(pair.get_attribute("data-tick"))
    clean_page.locator("#seek").fill(str(tick))
    clean_page.locator("#ov-flashes").check()
    assert not np.array_equal(shot(canvas), _png(folder, tick))
    clean_page.select_option("#zoom", "2")
    for key in ("velocity", "labels"):
        clean_page.locator(f"#ov-{key}").check()
    save_screenshot(clean_page.locator("body"), "viewer.png")


def test_paper_overlap_before_the_undo_is_shown_at_its_tick(clean_page, tmp_path):
    out = tmp_path / "out"
    path = ROOT / "scenarios" / "fig2_case1.yaml"  # asks for the overlap overlay
    assert main.main(["run", str(path), "--out", str(out), "--viewer", "--no-gif", "--quiet"]) == 0
    canvas = _open(clean_page, (out / "fig2_case1" / "viewer.html").as_uri())
    assert clean_page.locator("#ov-overlap").is_checked()
    for k, area in ((0, 0), (1, 16 * 1), (2, 0)):  # xdiff 16, ydiff 1 at tick 1
        clean_page.locator("#seek").fill(str(k))
        red = (shot(canvas) == (255, 0, 0)).all(axis=2)
        assert red.sum() == area, k
    clean_page.locator("#seek").fill("1")
    ys, xs = np.nonzero((shot(canvas) == (255, 0, 0)).all(axis=2))
    assert (xs.min(), xs.max(), ys.min(), ys.max()) == (104, 119, 110, 110)
    clean_page.locator("#ov-overlap").uncheck()
    assert not (shot(canvas) == (255, 0, 0)).all(axis=2).any()


def test_a_name_that_opens_a_comment_or_a_script_leaves_the_viewer_working(clean_page, tmp_path):
    """Found by hardening: an object named `<!--<script>` kept the viewer from starting."""
    names = ["<!--<script>", "</script><script>document.body.dataset.pwned=1</script>"]
    objects = "".join(
        f"  - {{shape: box, size: 4, position: [{10 * i + 2}, 4], velocity: [5, 0], "
        f"name: '{name}'}}\n"
        for i, name in enumerate(names)
    )
    path = tmp_path / "names.yaml"
    path.write_text(f"version: 1\nworld: {{width: 40, height: 20}}\nticks: 5\nobjects:\n{objects}")
    argv = ["run", str(path), "--out", str(tmp_path / "out"), "--viewer", "--no-gif", "--quiet"]
    assert main.main(argv) == 0
    _open(clean_page, (tmp_path / "out" / "names" / "viewer.html").as_uri())
    assert clean_page.locator("#status").text_content() == "6 frames"
    assert clean_page.locator("body").get_attribute("data-pwned") is None
    assert (
        clean_page.evaluate("JSON.parse(document.getElementById('data').textContent).names")
        == names
    )


def test_a_run_drawing_rests_opens_with_its_other_overlays_checked(clean_page, tmp_path):
    """The viewer draws no `rests` (docs/outputs.md#viewer): a run whose frames draw it opens
    with the overlays it does draw checked, without a script error."""
    out = tmp_path / "out"
    path = ROOT / "scenarios" / "exact_ledges.yaml"
    argv = ["run", str(path), "--out", str(out), "--viewer", "--no-gif", "--quiet"]
    assert main.main([*argv, "--ticks", "20", "--overlay", "rests,boxes"]) == 0
    _open(clean_page, (out / "exact_ledges" / "viewer.html").as_uri())
    assert clean_page.locator("#ov-boxes").is_checked()
    assert not clean_page.locator("#ov-velocity").is_checked()
    assert clean_page.locator("#ov-rests").count() == 0
