"""Tests of runner/output/overlay.py and the paper model's `advance_to_response`: overlays draw in
their own colours where they say, the run underneath is unchanged, Figure 2's frames show the
overlap xdiff wide and ydiff tall, and goldens see overlays only when the scenario asks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from collide2d.engine import models
from collide2d.runner.command import main
from collide2d.runner.output.overlay import COLORS, LABEL_MAX_PX, Overlay, Staged, labels
from collide2d.runner.run import drive, simulate
from collide2d.runner.scenario.load import ScenarioError, load, loads

ROOT = Path(__file__).resolve().parents[2]


def _scn(name, **overrides):
    return load(ROOT / "scenarios" / f"{name}.yaml", overrides=overrides or None)


@pytest.mark.parametrize("name", ["fig2_case1", "paper_fifty_boxes", "wall_bounces"])
def test_stopping_before_the_response_changes_nothing(name):
    scn = _scn(name, ticks=80)
    plain = models.make("paper", scn.world, scn.bodies)
    staged = Staged(models.make("paper", scn.world, scn.bodies))
    for chunk in (1, 7, 30, 42):
        a, b = plain.advance(chunk), staged.advance(chunk)
        assert np.array_equal(a, b)
    assert np.array_equal(plain.positions(), staged.positions())
    assert np.array_equal(plain.velocities(), staged.velocities())
    assert plain.event_counts() == staged.event_counts()


@pytest.mark.parametrize("case", [1, 2, 3, 4])
def test_figure_2_frame_1_shows_the_overlap_xdiff_by_ydiff(case):
    scn = _scn(f"fig2_case{case}")
    assert scn.output.overlay == ("overlap",)  # the scenarios ask for it
    result = simulate(scn, keep_frames=(0, 1, 2))
    (pair,) = result.events
    assert pair["tick"] == 1
    red = (result.frames[1] == COLORS["overlap"]).all(axis=2)
    ys, xs = np.nonzero(red)
    assert red.sum() == pair["xdiff"] * pair["ydiff"]
    assert (xs.max() - xs.min() + 1, ys.max() - ys.min() + 1) == (pair["xdiff"], pair["ydiff"])
    for k in (0, 2):  # no pair event at these ticks: nothing drawn
        colors = {tuple(c) for c in result.frames[k].reshape(-1, 3)}
        assert tuple(COLORS["overlap"]) not in colors and tuple(COLORS["ghost"]) not in colors
    # without the overlay the run is the same and frame 1 is the plain picture
    plain = simulate(
        scn.__class__(**{**scn.__dict__, "output": _no_overlay(scn)}), keep_frames=(0, 1, 2)
    )
    assert np.array_equal(plain.events, result.events)
    assert np.array_equal(plain.final_pos, result.final_pos)
    assert np.array_equal(plain.frames[0], result.frames[0])
    changed = (plain.frames[1] != result.frames[1]).any(axis=2)
    painted = red | (result.frames[1] == COLORS["ghost"]).all(axis=2)
    assert np.array_equal(changed, painted)  # only the overlay's pixels differ


def _no_overlay(scn):
    import dataclasses

    return dataclasses.replace(scn.output, overlay=())


def test_overlays_draw_in_their_colours_over_a_copy():
    scn = _scn("shapes_showcase", ticks=12)
    layer = Overlay(scn, ("velocity", "boxes", "contacts", "labels"))
    seen = {}

    def keep(k, idx):
        seen[k] = idx.copy()

    drive(scn, frames=(0, 12), on_frame=keep, log_events=True, overlay=layer)
    base = len(scn.palette)
    for k, idx in seen.items():
        used = set(np.unique(idx).tolist())
        assert {base, base + 1, base + 3} <= used, k  # velocity, boxes, labels
    rgb = layer.palette[seen[0]]
    # the static post (6x30 at 150,100) outlined by its box in the boxes colour
    assert (rgb[100, 150:156] == COLORS["boxes"]).all() and (
        rgb[129, 150:156] == COLORS["boxes"]
    ).all()
    assert (rgb[100:130, 150] == COLORS["boxes"]).all()


def test_a_long_name_is_cut_with_an_ellipsis_instead_of_overflowing():
    """Found by hardening: a long name (here the longest a name may be) ran its label off the
    frame."""
    long, short = "W" * 100, "ab"
    scn = loads(
        "version: 1\nworld: {width: 400, height: 40}\nticks: 1\nobjects:\n"
        f"  - {{shape: box, size: 2, position: [10, 30], name: {long}}}\n"
        f"  - {{shape: box, size: 2, position: [300, 30], name: {short}}}\n"
        '  - {shape: box, size: 2, position: [350, 30], name: "x\\e[2J\\ny"}\n'
    )
    layer = Overlay(scn, ("labels",))
    seen = {}
    drive(scn, frames=(0,), on_frame=lambda k, idx: seen.setdefault(k, idx.copy()), overlay=layer)
    cols = np.nonzero((seen[0] == len(scn.palette)).any(axis=0))[0]
    left = cols[cols < 250]  # the long name's label
    assert 10 <= left.min() and left.max() < 10 + LABEL_MAX_PX
    cut, kept, one_line = labels(scn.names, LABEL_MAX_PX)
    assert cut.endswith(("…", "...")) and long.startswith(cut.rstrip(".…"))
    assert len(cut) > 5 and kept == short and one_line == "x\\x1b[2J\\ny"


def test_contacts_ring_the_objects_of_an_event_at_the_frame():
    scn = _scn("fig2_case1")
    layer = Overlay(scn, ("contacts",))
    seen = {}
    drive(
        scn, frames=(0, 1), on_frame=lambda k, idx: seen.__setitem__(k, idx.copy()), overlay=layer
    )
    ring = len(scn.palette)
    assert not (seen[0] == ring).any() and (seen[1] == ring).any()


def test_an_overlay_that_reads_no_events_keeps_none_of_a_logged_run():
    """A run logging its events with only `velocity` drawn kept every chunk until the end."""
    scn = _scn("wall_bounces", ticks=40)
    layer = Overlay(scn, ("velocity",))
    drive(scn, frames=(0, 40), on_frame=lambda k, idx: None, log_events=True, overlay=layer)
    assert not layer.wants_events and layer._pending == []


def test_overlay_names_are_checked(tmp_path, capsys):
    with pytest.raises(ScenarioError, match="did you mean 'overlap'"):
        loads("version: 1\noutput: {overlay: [overlapp]}\n")
    assert loads("version: 1\noutput: {overlay: [labels, boxes]}\n").output.overlay == (
        "boxes",
        "labels",
    )
    with pytest.raises(SystemExit):
        main.main(["run", str(ROOT / "scenarios" / "fig2_case1.yaml"), "--overlay", "arrows"])
    assert "unknown overlay arrows" in capsys.readouterr().err


def test_run_overlay_reaches_png_and_gif_but_never_goldens(tmp_path):
    path = ROOT / "scenarios" / "wall_bounces.yaml"
    argv = ["run", str(path), "--out", str(tmp_path), "--png", "--quiet", "--ticks", "20"]
    assert main.main([*argv, "--overlay", "velocity"]) == 0
    folder = tmp_path / "wall_bounces"
    drawn = np.array(Image.open(folder / "frames" / "frame_000000.png").convert("RGB"))
    with Image.open(folder / "animation.gif") as gif:
        first = np.array(gif.convert("RGB"))
    assert np.array_equal(first, drawn)  # the GIF shows the overlay too
    # the golden run of the scenario (which asks for no overlay) draws none
    scn = _scn("wall_bounces", ticks=20)
    frame = simulate(scn, keep_frames=(0,)).frames[0]
    arrows = (drawn != frame).any(axis=2)
    assert arrows.any() and (drawn[arrows] == COLORS["velocity"]).all()
    assert main.main([*argv, "--overlay", "none"]) == 0
    png = np.array(Image.open(folder / "frames" / "frame_000000.png").convert("RGB"))
    assert np.array_equal(png, frame)
