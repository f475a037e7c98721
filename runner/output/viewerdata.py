"""The run viewer's data: every frame's positions, the sprites and the events, packed compactly.

`collide2d run --viewer` (or `output: {viewer: true}`) writes `viewer.html` beside the GIF: one
self-contained file (`runner.output.viewerpage` holds its page and script) that plays the run on a
canvas. A `Recorder` is handed each tick's model by the driver loop (`runner.run.drive`'s
`on_tick`) and the event chunks as they come; `page()` returns the HTML.

What the file holds, as JSON in the page:
- the world (size, fps, ticks, background colour) and per object its name, RGB colour and kind;
- the sprites (`engine.picture.sprites`): each object's pixels relative to its rounded position,
exactly
  the pixels `engine.picture.raster` draws, so the canvas at zoom 1 shows the PNG frames' very
  pixels;
- positions: the rounded pixel position of every object at every frame (0..ticks), as int32,
  object by object, each series stored as its first value then differences, zlib-compressed and
  base64-encoded (steady motion is a run of equal differences, which deflate squeezes to almost
  nothing); the browser inflates it with its own `DecompressionStream`;
- velocities (px/s, float32, the same layout, not differenced), for the velocity arrows;
- the events (tick, type, ids, side or axis), at most `MAX_EVENTS` of them (the count of the rest
  is shown);
- in a failing check's report, the golden's frames (`set_ghost`, RGB bytes packed like the
  positions, with their frame numbers), drawn as a ghost over the run at those frames;
- for the `paper` model, each pair event's overlap before the take-back (`runner.output.overlay`),
as
  int32 rows of OVERLAP_COLUMNS, packed like the positions.

A run of more than `MAX_POSITIONS` object-frames (ticks + 1 times objects) is refused before the
first tick: its viewer would not open quickly.
"""

from __future__ import annotations

import base64
import zlib

import numpy as np

from collide2d.engine.events import EV_PAIR, event_dict
from collide2d.engine.picture.raster import round_positions
from collide2d.engine.picture.sprites import sprites
from collide2d.runner.scenario.load import ScenarioError

VIEWER_FILE = "viewer.html"
# The most object-frames a viewer holds ((ticks + 1) x objects): 8 bytes each while recording.
MAX_POSITIONS = 20_000_000
# The most events listed in a viewer.
MAX_EVENTS = 50_000
# Positions are clamped to this many px from the origin (an int32; such an object is off screen).
POSITION_CLAMP = 2**30
ZLIB_LEVEL = 9
# The most golden frames a viewer shows as its ghost.
MAX_GHOST_FRAMES = 100
# An overlap row: tick, a, b, xdiff, ydiff, the overlap x0 y0 x1 y1 (exclusive ends; all 0 when
# empty), where a and b were (x, y each), as the pair rule saw them.
OVERLAP_COLUMNS = 13


def packed(array: np.ndarray) -> str:
    """base64 of the zlib-compressed little-endian bytes of `array`."""
    data = np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<"), copy=False)
    return base64.b64encode(zlib.compress(data.tobytes(), ZLIB_LEVEL)).decode("ascii")


def differenced(series: np.ndarray) -> np.ndarray:
    """(objects, frames, 2) int32 -> the same with each series' first value kept and every later
    value replaced by its difference from the one before (wrapping int32 arithmetic)."""
    out = series.copy()
    out[:, 1:] = series[:, 1:] - series[:, :-1]
    return out


class Recorder:
    """Collects one run's frames for its viewer; `add(model)` once per tick from 0, then
    `page()`. Raises ScenarioError at once when the run is too long to view."""

    def __init__(self, scenario, layer=None):
        n, frames = scenario.bodies.n, scenario.ticks + 1
        if n * frames > MAX_POSITIONS:
            raise ScenarioError(
                scenario.path or "<scenario>",
                1,
                1,
                f"a viewer of {frames:,} frames of {n:,} objects would hold {n * frames:,} "
                f"positions, past its limit of {MAX_POSITIONS:,}; run fewer ticks (--ticks) "
                "or drop --viewer",
            )
        self.scenario = scenario
        self.pos = np.zeros((frames, n, 2), np.int32)
        self.vel = np.zeros((frames, n, 2), np.float32)
        self.count = 0
        self.event_rows: list = []
        self.n_events = 0
        # a runner.output.overlay.Overlay noting the paper model's overlaps, or None
        self.layer = layer
        self.overlap_rows: list = []
        self._last = None
        self.ghost: dict = {}  # frame -> (H, W, 3) uint8 RGB: the golden's frames (`set_ghost`)

    def add(self, model) -> None:
        """Record the model's state as the next frame."""
        k = self.count
        ipos = round_positions(model.positions())
        self.pos[k] = np.clip(ipos, -POSITION_CLAMP, POSITION_CLAMP)
        self.vel[k] = model.velocities()
        self.count += 1
        staged = self.layer.staged if self.layer is not None else None
        if staged is not None and self._last is not None:
            now = self._last[self._last["tick"] == k]
            for a, b, xd, yd, rect, pa, pb in self.layer.pair_overlaps(k, now):
                if len(self.overlap_rows) < MAX_EVENTS:
                    self.overlap_rows.append([k, a, b, xd, yd, *(rect or (0, 0, 0, 0)), *pa, *pb])
            staged.forget_before(k + 1)

    def events(self, events: np.ndarray) -> None:
        """Keep an event chunk (EVENT_DTYPE records) for the list, up to MAX_EVENTS."""
        self._last = events[events["tick"] == events["tick"][-1]] if len(events) else None
        room = MAX_EVENTS - len(self.event_rows)
        for rec in events[: max(room, 0)]:
            d = event_dict(rec)
            kind = int(rec["type"])  # engine.events: wall, pair, rest, stop, wake, leave
            detail = d.get("side") or d.get("axis") or ""
            if "on" in d:  # rests on (stops, wakes from, leaves) a static box
                detail += f" on {d['on']}"
            if "xdiff" in d:
                detail += f" xdiff {d['xdiff']} ydiff {d['ydiff']}"
            b = int(rec["b"]) if kind == EV_PAIR else -1
            self.event_rows.append([int(rec["tick"]), kind, int(rec["a"]), b, detail])
        self.n_events += len(events)

    def set_ghost(self, frames: dict) -> None:
        """Show `frames` (frame number -> (H, W, 3) uint8 RGB, the golden's frames) as a ghost
        over the run at their frames: those of the world's size within the run, at most
        MAX_GHOST_FRAMES of them (the first)."""
        w, h = int(self.scenario.world.width), int(self.scenario.world.height)
        ticks = [
            k
            for k in sorted(frames)
            if 0 <= k <= self.scenario.ticks and frames[k].shape == (h, w, 3)
        ]
        self.ghost = {k: frames[k] for k in ticks[:MAX_GHOST_FRAMES]}

    def data(self) -> dict:
        """The JSON-ready data of the page."""
        scn = self.scenario
        start, offsets = sprites(scn.bodies)
        colors = scn.palette[np.asarray(scn.bodies.looks.color, np.int64)]
        names = [nm if nm else f"#{i}" for i, nm in enumerate(scn.names)]
        pos = self.pos[: self.count].transpose(1, 0, 2)  # object by object
        vel = self.vel[: self.count].transpose(1, 0, 2)
        return {
            "name": scn.name,
            "model": scn.model,
            "width": int(scn.world.width),
            "height": int(scn.world.height),
            "fps": int(scn.world.fps),
            "frames": int(self.count),
            "background": [int(c) for c in scn.palette[0]],
            "names": names,
            "colors": colors.astype(int).tolist(),
            "static": np.asarray(scn.bodies.static, bool).astype(int).tolist(),
            "spriteStart": start.astype(int).tolist(),
            "sprites": packed(offsets.astype(np.int32)),
            "positions": packed(differenced(np.ascontiguousarray(pos))),
            "velocities": packed(np.ascontiguousarray(vel)),
            "events": self.event_rows,
            "overlaps": packed(np.array(self.overlap_rows, np.int32).reshape(-1, OVERLAP_COLUMNS)),
            "paper": scn.model == "paper",
            # the overlays the run draws into its frames (`run --overlay`, else the scenario's)
            "overlay": list(self.layer.names if self.layer is not None else scn.output.overlay),
            "eventCount": int(self.n_events),
            "ghostFrames": sorted(self.ghost),
            "ghost": packed(
                np.array([self.ghost[k] for k in sorted(self.ghost)], np.uint8).reshape(-1)
            ),
        }

    def page(self) -> bytes:
        """viewer.html bytes."""
        from collide2d.runner.output.viewerpage import page  # its text loads only when asked for

        return page(self.data())
