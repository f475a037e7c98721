"""Debug overlays drawn into PNG and GIF frames: velocity arrows, boxes, contact flashes, labels,
for the `paper` model the overlap a pair had before the model took its step back, and for the
`exact` model under gravity what rests on what.

Asked for by `output: {overlay: [...]}` in a scenario (then its goldens show them too: the scenario
asked) or by `collide2d run --overlay a,b` (that run's files only; goldens never see them). The
names (`OVERLAYS`):

- `velocity`: a line from each moving object's centre along half a second of its motion, with a
  two-stroke head;
- `boxes`: each object's pixel extent, outlined;
- `contacts`: a ring around each object of an event at the frame's tick (wall and pair events,
  and under gravity rest, stop, wake and leave);
- `labels`: each object's name above it (Pillow's default font, without smoothing), on one line
  (control characters spelled out, `runner.output.escape.one_line`) and at most LABEL_MAX_PX wide: a
  longer name is cut and ends in an ellipsis;
- `overlap` (`paper` only; other models draw nothing for it): for each pair event at the frame's
  tick, both boxes where the pair rule saw them (`engine.models.paper.Model.advance_to_response`:
  moved, before any pair took its step back) outlined in grey over the background, and their
  overlap filled in red: a rectangle `xdiff` wide and `ydiff` tall, the picture of the paper's
  Figure 2 (the frame itself shows the boxes after the take-back). The rule sees later pairs of a
  tick after earlier ones took steps back; the rectangle is drawn from the positions before any
  pair of the tick, exact for the first pair of each object;
- `rests` (`exact` under gravity; other models log no rests and draw nothing for it): for each
  object resting at the frame's tick (`runner.output.rests`: from its `rest` event until its
  `wake` or `leave`, and from tick 0 on a wall it starts still against), a line from its centre
  to its edge on the side it presses into (straight below the centre for `bottom`), a mark
  across the contact on the support's face (2 * MARK_PX + 1 px; for a wall, on the frame's edge)
  and, when the support is an object, a line on to that object's centre, so a stack shows as a
  chain down to what bears it.

Overlays are drawn over the frame's palette indices in colours added after the scenario's palette
(`Overlay.palette`), so the frames stay exact palette images and the GIF needs no quantising.
`Overlay.wrap(model)` runs a paper model tick by tick, stopping before each response stage to
note the positions the rule sees (`Staged`); the run's results are the same (a test checks).
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from collide2d.engine.events import EV_PAIR, SIDE_BOTTOM, SIDE_LEFT, SIDE_RIGHT, SIDE_TOP
from collide2d.engine.picture.pixels import dda_line, midpoint_circle
from collide2d.engine.picture.raster import round_positions
from collide2d.engine.picture.sprites import sprites
from collide2d.runner.output import escape
from collide2d.runner.output.rests import WALL, Rests
from collide2d.runner.scenario.load import ScenarioError
from collide2d.runner.scenario.sections import OVERLAY_NAMES

OVERLAYS = OVERLAY_NAMES
# Colours (RGB) of the overlays, added after the scenario's palette in this order.
COLORS = {
    "velocity": (255, 255, 0),
    "boxes": (0, 200, 255),
    "contacts": (255, 96, 0),
    "labels": (255, 255, 255),
    "overlap": (255, 0, 0),
    "rests": (0, 230, 0),
    "ghost": (200, 200, 200),
}
# An arrow shows this many seconds of motion; its head's strokes are HEAD_PX long.
ARROW_SECONDS = 0.5
HEAD_PX = 4
# A contact ring's gap around the object (px).
RING_GAP_PX = 3
# The widest a label is drawn (px; and never wider than the frame): a longer name is cut and ends
# in an ellipsis (about 15 characters of the default font).
LABEL_MAX_PX = 96
# A rest's mark across the contact reaches this far (px) each side of it.
MARK_PX = 3
MAX_PALETTE = 256


def extents(bodies) -> np.ndarray:
    """(n, 4) int64 inclusive pixel box (x0, y0, x1, y1) of each object around its rounded
    position, from its sprite ((0, 0, -1, -1) for an object that draws nothing)."""
    start, offsets = sprites(bodies)
    ext = np.tile(np.array([0, 0, -1, -1], np.int64), (len(start) - 1, 1))
    for i in range(len(start) - 1):
        pts = offsets[start[i] : start[i + 1]]
        if len(pts):
            ext[i] = (*pts.min(axis=0), *pts.max(axis=0))
    return ext


class Staged:
    """A paper model run tick by tick that notes, at each tick with pair events, the positions the
    pair rule saw (`before[tick]`, float64 (n, 2)); everything else is the model's own."""

    def __init__(self, model):
        self._model = model
        self.before: dict[int, np.ndarray] = {}

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        chunks = []
        for _ in range(int(ticks)):
            walls = self._model.advance_to_response(log)
            seen = self._model.positions().copy()
            rest = self._model.advance(1, log)
            if len(rest) and (rest["type"] == EV_PAIR).any():
                self.before[self._model.tick] = seen
            chunks.extend(c for c in (walls, rest) if len(c))
        if not chunks:
            return self._model.advance(0, log)
        return np.concatenate(chunks)

    def forget_before(self, tick: int) -> None:
        """Drop the notes of ticks before `tick` (they were drawn)."""
        for k in [k for k in self.before if k < tick]:
            del self.before[k]

    def __getattr__(self, name):
        return getattr(self._model, name)


def overlaps(bodies, before: np.ndarray, events: np.ndarray) -> list:
    """[(a, b, xdiff, ydiff, (x0, y0, x1, y1) of the overlap or None, pos_a, pos_b)] of the pair
    events, boxes at `before` (the paper model's whole-pixel positions)."""
    out = []
    size = np.asarray(bodies.size, np.int64)
    pos = round_positions(before)
    for rec in events[events["type"] == EV_PAIR]:
        a, b = int(rec["a"]), int(rec["b"])
        x0 = max(pos[a, 0], pos[b, 0])
        y0 = max(pos[a, 1], pos[b, 1])
        x1 = min(pos[a, 0] + size[a, 0], pos[b, 0] + size[b, 0])
        y1 = min(pos[a, 1] + size[a, 1], pos[b, 1] + size[b, 1])
        rect = (int(x0), int(y0), int(x1), int(y1)) if x1 > x0 and y1 > y0 else None
        out.append(
            (a, b, int(rec["xdiff"]), int(rec["ydiff"]), rect, pos[a].tolist(), pos[b].tolist())
        )
    return out


class Overlay:
    """The overlays `names` of one scenario's run; `record`: note the paper model's pair overlaps
    even when none is drawn (for the viewer)."""

    def __init__(self, scenario, names=(), record: bool = False):
        self.scenario = scenario
        self.names = tuple(n for n in OVERLAYS if n in set(names))
        self.paper = scenario.model == "paper"
        self.record = self.paper and (record or "overlap" in self.names)
        base = np.asarray(scenario.palette, np.uint8)
        keys = [*self.names, *(["ghost"] if "overlap" in self.names else [])]
        self.index = {k: base.shape[0] + j for j, k in enumerate(keys)}
        if base.shape[0] + len(keys) > MAX_PALETTE:
            raise ScenarioError(
                scenario.path or "<scenario>",
                1,
                1,
                f"the overlays {', '.join(self.names)} need {len(keys)} colours besides the "
                f"scenario's {base.shape[0]}, past the {MAX_PALETTE} a frame may have",
            )
        extra = np.array([COLORS[k] for k in keys], np.uint8).reshape(-1, 3)
        self.palette = np.concatenate([base, extra]) if len(keys) else base
        self.ext = extents(scenario.bodies) if self.names else None
        self.staged: Staged | None = None
        self._pending: list = []
        self._labels: list[str] | None = None
        self.rests = Rests() if "rests" in self.names else None

    @property
    def wants_events(self) -> bool:
        return self.record or "contacts" in self.names or self.rests is not None

    def wrap(self, model):
        """The model to run: a `Staged` paper model when overlaps are noted, else `model`."""
        if self.rests is not None:
            self.rests.start(model)
        if self.record:
            self.staged = Staged(model)
            return self.staged
        return model

    def events(self, events: np.ndarray) -> None:
        """Take an event chunk (the chunks end at frame ticks; every tick's events come, those
        of ticks no frame draws too)."""
        if not self.wants_events:
            return  # a run that logs events for its file: nothing here reads them
        self._pending.append(events)
        if self.rests is not None:
            self.rests.events(events)

    def at(self, tick: int) -> np.ndarray:
        """The events of `tick` among those taken (older ones are dropped)."""
        if self._pending:
            self._pending = [np.concatenate(self._pending)]
            ev = self._pending[0]
            self._pending = [ev[ev["tick"] >= tick]]
            return ev[ev["tick"] == tick]
        return np.zeros(0)

    def pair_overlaps(self, tick: int, events) -> list:
        """The overlaps of the pair events of `tick` (paper, when noted), else []."""
        if self.staged is None or tick not in self.staged.before or not len(events):
            return []
        return overlaps(self.scenario.bodies, self.staged.before[tick], events)

    def draw(self, k: int, idx: np.ndarray, model) -> np.ndarray:
        """A copy of the index frame `idx` of tick k with the overlays drawn over it."""
        events = self.at(k) if self.wants_events else np.zeros(0)
        resting = self.rests.at(k) if self.rests is not None else {}
        if not self.names:
            return idx
        notes = self.pair_overlaps(k, events) if "overlap" in self.names else []
        if self.staged is not None and "overlap" in self.names:
            self.staged.forget_before(k + 1)
        out = idx.copy()
        ipos = round_positions(model.positions())
        vel = np.asarray(model.velocities(), np.float64)
        pen = _Pen(out)
        ext = self.ext
        if "boxes" in self.names:
            for i in range(ipos.shape[0]):
                x0, y0, x1, y1 = ext[i]
                if x1 >= x0:
                    pen.rect(ipos[i, 0] + x0, ipos[i, 1] + y0, ipos[i, 0] + x1, ipos[i, 1] + y1,
                             self.index["boxes"])  # fmt: skip
        if "overlap" in self.names:
            size = np.asarray(self.scenario.bodies.size, np.int64)
            for a, b, _xd, _yd, rect, pa, pb in notes:
                for i, p in ((a, pa), (b, pb)):
                    pen.rect(p[0], p[1], p[0] + size[i, 0] - 1, p[1] + size[i, 1] - 1,
                             self.index["ghost"], under=True)  # fmt: skip
                if rect is not None:
                    pen.fill(rect[0], rect[1], rect[2] - 1, rect[3] - 1, self.index["overlap"])
        for x0, y0, x1, y1 in rest_lines(resting, ipos, ext, out.shape[1], out.shape[0]):
            pen.line(x0, y0, x1, y1, self.index["rests"])
        if "velocity" in self.names:
            for i in range(ipos.shape[0]):
                if not (vel[i] != 0).any() or ext[i, 2] < ext[i, 0]:
                    continue
                cx, cy = _centre(ipos[i], ext[i])
                d = vel[i] * ARROW_SECONDS
                tx, ty = int(round(cx + d[0])), int(round(cy + d[1]))
                pen.line(cx, cy, tx, ty, self.index["velocity"])
                ang = np.arctan2(ty - cy, tx - cx)
                for turn in (2.6, -2.6):
                    hx = int(round(tx + HEAD_PX * np.cos(ang + turn)))
                    hy = int(round(ty + HEAD_PX * np.sin(ang + turn)))
                    pen.line(tx, ty, hx, hy, self.index["velocity"])
        if "contacts" in self.names and len(events):
            for rec in events:
                ids = [int(rec["a"])] + ([int(rec["b"])] if rec["type"] == EV_PAIR else [])
                for i in ids:
                    x0, y0, x1, y1 = ext[i]
                    side = max(x1 - x0, y1 - y0) + 1 + 2 * RING_GAP_PX
                    cx = ipos[i, 0] + (x0 + x1) // 2 - side // 2
                    cy = ipos[i, 1] + (y0 + y1) // 2 - side // 2
                    pen.points(midpoint_circle(side) + (cx, cy), self.index["contacts"])
        if "labels" in self.names:
            if self._labels is None:  # the same for every frame
                self._labels = labels(_names(self.scenario), min(LABEL_MAX_PX, idx.shape[1]))
            pen.labels(ipos, ext, self._labels, self.index["labels"])
        return out


def rest_lines(resting: dict, ipos, ext, width: int, height: int) -> list:
    """[(x0, y0, x1, y1)] pixel lines of the `rests` overlay, objects in id order: for each
    resting object i, from its centre to its edge pixel on its side, the mark across the contact
    on the support's face (the pixel past that edge, kept inside the frame: a wall's is the
    frame's edge pixel) and, on an object, from there to that object's centre."""
    lines = []
    for i in sorted(resting):
        side, support = resting[i]
        if ext[i, 2] < ext[i, 0]:
            continue  # draws nothing
        cx, cy = _centre(ipos[i], ext[i])
        x0, y0 = ipos[i, 0] + ext[i, 0], ipos[i, 1] + ext[i, 1]
        x1, y1 = ipos[i, 0] + ext[i, 2], ipos[i, 1] + ext[i, 3]
        ex, ey, dx, dy = {
            SIDE_BOTTOM: (cx, y1, 0, 1),
            SIDE_TOP: (cx, y0, 0, -1),
            SIDE_LEFT: (x0, cy, -1, 0),
            SIDE_RIGHT: (x1, cy, 1, 0),
        }[side]
        fx = int(min(max(ex + dx, 0), width - 1))
        fy = int(min(max(ey + dy, 0), height - 1))
        lines.append((cx, cy, int(ex), int(ey)))
        lines.append((fx - MARK_PX * dy, fy - MARK_PX * dx, fx + MARK_PX * dy, fy + MARK_PX * dx))
        if support != WALL and ext[support, 2] >= ext[support, 0]:
            lines.append((fx, fy, *_centre(ipos[support], ext[support])))
    return lines


def _names(scenario) -> list[str]:
    return [nm if nm else f"#{i}" for i, nm in enumerate(scenario.names)]


def labels(names, max_px: int) -> list[str]:
    """The text drawn for each name: one line, at most `max_px` wide in the default font; a
    longer name is cut, ending in an ellipsis (`...` in a bitmap font without `…`, which also
    draws only Latin-1: other characters become `?`)."""
    font = ImageFont.load_default()
    draw = ImageDraw.Draw(Image.new("1", (1, 1)))
    outline = isinstance(font, ImageFont.FreeTypeFont)
    ellipsis = "…" if outline else "..."

    def width(text: str) -> float:
        return draw.textlength(text, font=font)

    out = []
    for name in names:
        text = escape.one_line(name)
        if not outline:
            text = text.encode("latin-1", "replace").decode("latin-1")
        # a name of more than max_px characters is cut whatever it holds (nearly every glyph
        # is a pixel wide or more), so that a long name is never measured whole
        if len(text) > max_px or width(text) > max_px:
            lo, hi = 0, min(len(text), max_px)  # the longest prefix that fits with the ellipsis
            while lo < hi:
                mid = (lo + hi + 1) // 2
                lo, hi = (mid, hi) if width(text[:mid] + ellipsis) <= max_px else (lo, mid - 1)
            text = text[:lo] + ellipsis
        out.append(text)
    return out


def _centre(p, e) -> tuple[int, int]:
    return int(p[0] + (e[0] + e[2]) // 2), int(p[1] + (e[1] + e[3]) // 2)


class _Pen:
    """Palette-index drawing on a frame, clipped to it."""

    def __init__(self, buf: np.ndarray):
        self.buf = buf
        self.h, self.w = buf.shape

    def points(self, pts: np.ndarray, color: int, under: bool = False) -> None:
        """Paint the points (k, 2) inside the frame; `under`: only over the background."""
        pts = np.asarray(pts, np.int64).reshape(-1, 2)
        ok = (pts[:, 0] >= 0) & (pts[:, 0] < self.w) & (pts[:, 1] >= 0) & (pts[:, 1] < self.h)
        pts = pts[ok]
        if under:
            pts = pts[self.buf[pts[:, 1], pts[:, 0]] == 0]
        self.buf[pts[:, 1], pts[:, 0]] = color

    def line(self, x0, y0, x1, y1, color: int, under: bool = False) -> None:
        self.points(dda_line(x0, y0, x1, y1), color, under)

    def rect(self, x0, y0, x1, y1, color: int, under: bool = False) -> None:
        for a, b, c, d in ((x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)):
            self.line(a, b, c, d, color, under)

    def fill(self, x0, y0, x1, y1, color: int) -> None:
        x0, y0 = max(int(x0), 0), max(int(y0), 0)
        x1, y1 = min(int(x1), self.w - 1), min(int(y1), self.h - 1)
        if x0 <= x1 and y0 <= y1:
            self.buf[y0 : y1 + 1, x0 : x1 + 1] = color

    def labels(self, ipos, ext, names, color: int) -> None:
        mask = Image.new("1", (self.w, self.h), 0)
        draw = ImageDraw.Draw(mask)
        draw.fontmode = "1"
        font = ImageFont.load_default()
        for i, name in enumerate(names):
            if ext[i, 2] < ext[i, 0]:
                continue
            x, y = int(ipos[i, 0] + ext[i, 0]), int(ipos[i, 1] + ext[i, 1])
            box = draw.textbbox((0, 0), name, font=font)
            draw.text((x, y - (box[3] - box[1]) - 3), name, fill=1, font=font)
        self.buf[np.array(mask, bool)] = color
