"""The report page: one self-contained HTML file a reviewer opens to see what changed and why.

Input: `report.Outcome`s (with their frames and texts) and the report folder. Output: the bytes of
`index.html`. Every image is inline (PNG data URIs) and the script and styles are inline, so the
file opens anywhere with no network and no other file. Every text from a scenario, a file name or
a golden goes through `_html`.

What the page shows, top to bottom: a summary line (`1 failed, 18 passed`), a "failures only"
filter and the keys; then one section per scenario, failures first (each group by name). A failed
section says why it changed (`why.Cause`: the scenario edited since bless, or the same scenario
under another collide2d), lists the problems, links the files of its report folder when the page
is written with one (`base`: the full logs, the full frames, the viewer), shows the event log diff
as a table (`eventdiff`: the logs aligned, objects named, folds that expand), and per differing
frame a crop around the changed pixels enlarged with nearest-neighbour pixels next to the full
frame (the crop's place outlined), in four views: side by side, blink (golden and run toggled in
place), a slider (golden left of the handle, run right of it, a divider between) and the diff.

Keys: j / k next / previous frame, n / p next / previous failing scenario, 1-4 or s / b / l / d the
view of the current frame (b again toggles blink), arrow keys move its slider, f the filter. Every
name, file name and golden text goes through `_html` (links: percent-encoded, then escaped).
"""

from __future__ import annotations

import base64
import html
import os
from pathlib import Path
from urllib.parse import quote

import numpy as np

from collide2d.runner.golden import eventdiff, serialize
from collide2d.runner.output.escape import visible
from collide2d.runner.output.files import encode_png
from collide2d.runner.output.viewerdata import VIEWER_FILE as VIEWER

# Crops: the changed pixels' box grown by CROP_MARGIN px on each side and to at least CROP_MIN px,
# enlarged by a whole factor to about CROP_TARGET px on its longer side (at most CROP_MAX_ZOOM).
CROP_MARGIN = 6
CROP_MIN = 24
CROP_TARGET = 240
CROP_MAX_ZOOM = 16
# What each report file is, as its link on the page says.
FILE_LABELS = {
    "events_expected.jsonl": "golden event log",
    "events_actual.jsonl": "this run's event log",
    "final_expected.csv": "golden final state",
    "final_actual.csv": "this run's final state",
}
FRAME_LABELS = {"expected": "golden", "actual": "this run", "diff": "diff"}
# Full frames narrower than this are shown at twice their size.
ZOOM_BELOW_PX = 480
VIEWS = ("side", "blink", "slider", "diff")
# The diff picture: differing pixels, pixels changed within the colour threshold, and the level of
# the run's frame dimmed to grey beneath them.
DIFF_COLOR = (255, 0, 255)
WITHIN_THRESHOLD_COLOR = (255, 176, 0)
DIM_LEVEL = 0.35


def _html(text) -> str:
    """`text` as page text: HTML-escaped, with control characters and a file name's undecodable
    bytes spelled out (`escape.visible`), so that any name, file name or golden text shows."""
    return html.escape(visible(str(text)))


def summary_line(outcomes) -> str:
    """`1 failed, 18 passed` (missing and unreadable goldens count as failed)."""
    failed = sum(not o.ok for o in outcomes)
    return f"{failed} failed, {len(outcomes) - failed} passed"


def ordered(outcomes) -> list:
    """Failures first, each group by name."""
    return sorted(outcomes, key=lambda o: (o.ok, o.name))


def crop_box(bbox, width: int, height: int) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) exclusive-end crop around the inclusive box `bbox` of changed pixels."""
    x0, y0, x1, y1 = bbox
    x0, y0, x1, y1 = x0 - CROP_MARGIN, y0 - CROP_MARGIN, x1 + 1 + CROP_MARGIN, y1 + 1 + CROP_MARGIN
    for lo, hi, size, axis in ((x0, x1, width, 0), (y0, y1, height, 1)):
        grow = max(0, min(CROP_MIN, size) - (hi - lo))
        lo, hi = lo - grow // 2, hi + grow - grow // 2
        shift = max(0, -lo) - max(0, hi - size)
        lo, hi = max(0, lo + shift), min(size, hi + shift)
        if axis == 0:
            x0, x1 = lo, hi
        else:
            y0, y1 = lo, hi
    return x0, y0, x1, y1


def crop_zoom(box) -> int:
    """The whole enlargement factor of a crop."""
    side = max(box[2] - box[0], box[3] - box[1])
    return max(1, min(CROP_MAX_ZOOM, CROP_TARGET // max(side, 1)))


def _uri(rgb: np.ndarray, zoom: int = 1) -> str:
    data = encode_png(np.ascontiguousarray(rgb), scale=zoom)
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def page(title: str, outcomes, unused=(), base=None) -> bytes:
    """index.html bytes over `outcomes` (any order; shown failures first). `base`: the folder the
    page is written in; a failure whose report folder is written links its files (the full logs,
    the full frames, the viewer) relative to it."""
    outcomes = ordered(outcomes)
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width">',
        f"<title>{_html(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{_html(title)}</h1>",
        f'<p id="summary" class="summary {"bad" if any(not o.ok for o in outcomes) else "good"}">'
        f"{_html(summary_line(outcomes))}</p>",
        '<p class="bar"><label><input type="checkbox" id="only-failures"> failures only '
        "(f)</label> <span class=keys>keys: <kbd>j</kbd>/<kbd>k</kbd> next/previous frame, "
        "<kbd>n</kbd>/<kbd>p</kbd> next/previous failure, <kbd>1</kbd>-<kbd>4</kbd> side by "
        "side / blink / slider / diff, <kbd>b</kbd> blink, <kbd>←</kbd>/<kbd>→</kbd> slider"
        "</span></p>",
        '<ul id="toc">',
    ]
    for o in outcomes:
        name = _html(o.name)
        parts.append(
            f'<li class="entry" data-status="{o.status}"><a href="#sc-{name}">{name}</a> '
            f'<span class="{o.status}">{o.status}</span></li>'
        )
    parts.append("</ul>")
    if unused:
        names = ", ".join(_html(n) for n in unused)
        parts.append(
            f"<p>Goldens no scenario uses: {names} "
            "(remove them with <code>collide2d bless --prune</code>).</p>"
        )
    parts.extend(_section(o, base) for o in outcomes)
    parts.append(f"<script>{_JS}</script></body></html>\n")
    return "\n".join(parts).encode("utf-8")


def _href(path, base) -> str:
    """The link to the file `path` from the folder `base`, percent-encoded (any bytes of a file
    name) and HTML-escaped."""
    rel = os.path.relpath(path, base)
    return html.escape(quote(os.fsencode(Path(rel).as_posix())))


def _link(path, base, text: str) -> str:
    return f'<a href="{_href(path, base)}">{_html(text)}</a>'


def _section(o, base=None) -> str:
    folder = Path(o.report).parent if o.report is not None and base is not None else None
    name = _html(o.name)
    out = [
        f'<section class="scenario" id="sc-{name}" data-status="{o.status}">',
        f'<h2>{name} <span class="{o.status}">{o.status}</span></h2>',
        f"<p>Scenario <code>{_html(o.scenario)}</code>.</p>",
    ]
    if o.ok:
        return "\n".join([*out, "</section>"])
    if o.cause is not None:
        out.append(
            f'<p class="why" data-kind="{_html(o.cause.kind)}"><b>Why it changed:</b> '
            f"{_html(o.cause.text)}</p>"
        )
    texts = [p for p in o.problems if isinstance(p, str)]
    if texts:
        out.append('<pre class="problems">' + _html("\n".join(texts)) + "</pre>")
    logs = ""
    if folder is not None:
        shown = [f for f in FILE_LABELS if f in o.texts] + sorted(set(o.texts) - set(FILE_LABELS))
        files = [_link(folder / f, base, FILE_LABELS.get(f, f)) for f in shown]
        if o.viewer is not None:
            files.insert(0, _link(folder / VIEWER, base, "viewer of this run"))
        if files:
            out.append('<p class="files">Files: ' + " · ".join(files) + "</p>")
        logs = " ".join(
            _link(folder / f, base, FILE_LABELS[f])
            for f in ("events_expected.jsonl", "events_actual.jsonl")
            if f in o.texts  # the logs again, where a fold too long to expand points to them
        )
    table = _event_table(o, logs)
    if table:
        out.append(table)
    for fr in o.frames:
        out.append(_frame_block(o.name, fr, base if folder is not None else None))
    out.append(f"<p>To accept this run: <code>{_html(o.bless)}</code></p>")
    out.append("</section>")
    return "\n".join(out)


def _event_table(o, links: str = "") -> str:
    """Golden and run events aligned side by side (`eventdiff`), objects by their names."""
    exp_bytes = o.texts.get("events_expected.jsonl")
    act_bytes = o.texts.get("events_actual.jsonl")
    if exp_bytes is None or act_bytes is None or o.first_event is None:
        return ""
    try:
        exp, act = serialize.parse_events(exp_bytes), serialize.parse_events(act_bytes)
    except ValueError:
        return ""
    caption = _html(
        f"Event log: golden vs this run ({len(exp)} vs {len(act)} events; first divergence at "
        f"#{o.first_event + 1})"
    )
    return eventdiff.table(exp, act, o.names, caption, links)


def diff_image(fr) -> np.ndarray | None:
    """The diff picture of a `report.FrameReport`, (H, W, 3) uint8: the run's frame in dim grey (its
    brightest channel times DIM_LEVEL), pixels changed within the colour threshold in
    WITHIN_THRESHOLD_COLOR, differing pixels in DIFF_COLOR; the report writes it as `_diff.png` and
    the page shows it as the diff view. None when there is nothing to overlay (sizes differ or one
    side is missing)."""
    d = fr.diff
    if d is None or d.size_mismatch or d.mask is None:
        return None
    grey = fr.actual.max(axis=2).astype(np.float64) * DIM_LEVEL
    out = np.repeat(grey.astype(np.uint8)[:, :, None], 3, axis=2)
    out[d.changed & ~d.mask] = WITHIN_THRESHOLD_COLOR
    out[d.mask] = DIFF_COLOR
    return out


def _frame_block(name: str, fr, base=None) -> str:
    key = _html(f"{name}-{fr.frame}")
    head = f'<div class="frame" id="f-{key}" data-view="side" tabindex="-1">'
    msg = f"<p class=msg>{_html(fr.message)}</p>"
    if base is not None and fr.paths:
        full = [_link(fr.paths[k], base, v) for k, v in FRAME_LABELS.items() if k in fr.paths]
        msg += '<p class="files">Full frames: ' + " · ".join(full) + "</p>"
    exp, act, d = fr.expected, fr.actual, fr.diff
    if d is None or d.size_mismatch or d.bbox is None:
        figures = [
            _figure(rgb, caption)
            for rgb, caption in ((exp, "golden"), (act, "this run"))
            if rgb is not None
        ]
        return head + msg + '<div class="fulls">' + "".join(figures) + "</div></div>"
    h, w = act.shape[:2]
    box = crop_box(d.bbox, w, h)
    zoom = crop_zoom(box)
    x0, y0, x1, y1 = box
    crops = {
        kind: _uri(rgb[y0:y1, x0:x1], zoom)
        for kind, rgb in (("expected", exp), ("actual", act), ("diff", diff_image(fr)))
    }
    cw, ch = (x1 - x0) * zoom, (y1 - y0) * zoom
    size = f'width="{cw}" height="{ch}"'
    views = "".join(
        f'<button type="button" data-view="{v}">{label}</button>'
        for v, label in zip(VIEWS, ("side by side", "blink", "slider", "diff"), strict=True)
    )
    crop_caption = (
        f"crop x {x0}..{x1 - 1}, y {y0}..{y1 - 1}, {zoom}x; changed pixels x {d.bbox[0]}.."
        f"{d.bbox[2]}, y {d.bbox[1]}..{d.bbox[3]}"
    )
    return (
        head
        + msg
        + f'<div class="views">{views} <span class="showing"></span></div>'
        + '<div class="crops">'
        + f'<div class="panel side"><figure><img {size} src="{crops["expected"]}" alt="golden">'
        + "<figcaption>golden</figcaption></figure>"
        + f'<figure><img {size} src="{crops["actual"]}" alt="this run">'
        + "<figcaption>this run</figcaption></figure>"
        + f'<figure><img {size} src="{crops["diff"]}" alt="diff">'
        + "<figcaption>diff</figcaption></figure></div>"
        + f'<div class="panel stack" style="width:{cw}px;height:{ch}px">'
        + f'<img class="under" {size} src="{crops["expected"]}" alt="golden">'
        + f'<img class="over" {size} src="{crops["actual"]}" alt="this run">'
        + '<span class="divider"></span></div>'
        + '<div class="panel slider"><input type="range" min="0" max="100" value="50" '
        + f'style="width:{cw}px" aria-label="slider"></div>'
        + f'<div class="panel diff"><img {size} src="{crops["diff"]}" alt="diff"></div>'
        + f"<p class=caption>{_html(crop_caption)}</p></div>"
        + '<div class="fulls">'
        + _figure(act, "this run, full frame", box)
        + "</div></div>"
    )


def _figure(rgb, caption: str, box=None) -> str:
    h, w = rgb.shape[:2]
    zoom = 2 if w < ZOOM_BELOW_PX else 1
    mark = ""
    if box is not None:
        x0, y0, x1, y1 = (v * zoom for v in box)
        mark = (
            f'<span class="mark" style="left:{x0}px;top:{y0}px;width:{x1 - x0}px;'
            f'height:{y1 - y0}px"></span>'
        )
    return (
        f'<figure><div class="full" style="width:{w * zoom}px;height:{h * zoom}px">'
        f'<img src="{_uri(rgb)}" width="{w * zoom}" height="{h * zoom}" alt="{caption}">'
        f"{mark}</div><figcaption>{_html(caption)} ({w}x{h})</figcaption></figure>"
    )


_CSS = """
body { font: 14px/20px system-ui, sans-serif; margin: 20px; background: #fafafa; color: #222; }
h1 { font-size: 20px; line-height: 28px; margin: 12px 0; } h2 { font-size: 16px; line-height: 24px;
  margin: 24px 0 8px; }
p { margin: 8px 0; }
.summary { font-size: 18px; line-height: 24px; font-weight: bold; }
.summary.bad { color: #cf222e; } .summary.good { color: #1a7f37; }
.passed { color: #1a7f37; } .failed, .missing, .unreadable { color: #cf222e; }
body.only-failures [data-status="passed"] { display: none; }
.why { background: #fff8c5; border: 1px solid #d4a72c; padding: 6px 8px; }
pre { background: #fff; border: 1px solid #ddd; padding: 8px; overflow-x: auto; line-height: 18px; }
.frame { background: #fff; border: 1px solid #ddd; padding: 12px; margin: 16px 0;
  display: flex; flex-wrap: wrap; gap: 16px; }
.frame.current { outline: 3px solid #0969da; }
.frame .msg, .frame .views { flex-basis: 100%; margin: 0; }
.views button { border: 1px solid #bbb; background: #fff; padding: 2px 10px; cursor: pointer;
  font: 13px/18px system-ui, sans-serif; }
.frame[data-view="side"] button[data-view="side"], .frame[data-view="blink"]
  button[data-view="blink"], .frame[data-view="slider"] button[data-view="slider"],
  .frame[data-view="diff"] button[data-view="diff"] { background: #222; color: #fff; }
.panel { display: none; margin-top: 10px; }
.frame[data-view="side"] .panel.side { display: flex; gap: 12px; }
.frame[data-view="blink"] .panel.stack, .frame[data-view="slider"] .panel.stack,
  .frame[data-view="slider"] .panel.slider, .frame[data-view="diff"] .panel.diff {
  display: block; }
.stack { position: relative; }
.stack img { position: absolute; left: 0; top: 0; }
.frame[data-view="blink"] .stack img.over { visibility: hidden; }
.frame[data-view="blink"].show-run .stack img.over { visibility: visible; }
.frame:not([data-view="slider"]) .stack img.over { clip-path: none !important; }
figure { margin: 0; } figcaption, .caption { font-size: 12px; line-height: 16px; color: #555; }
img { image-rendering: pixelated; display: block; }
.full { position: relative; border: 1px solid #999; }
.mark { position: absolute; outline: 2px solid #0969da; pointer-events: none; }
table.events { border-collapse: collapse; background: #fff; margin: 8px 0; }
table.events td, table.events th { border: 1px solid #ddd; padding: 2px 8px;
  font: 12px/16px ui-monospace, monospace; text-align: left; }
table.events tr.first { background: #ffd8d3; font-weight: bold; }
table.events tr.changed { background: #fff0ee; }
table.events tr.dropped { background: #ffe4e0; } table.events tr.inserted { background: #e2f5e5; }
table.events tr.dropped td:nth-child(4), table.events tr.inserted td:nth-child(2) {
  color: #999; }
table.events tr.folded { color: #555; }
table.events tr.gap td { color: #777; font-style: italic; }
.unfold { border: 0; background: none; padding: 0; color: #0969da; cursor: pointer;
  font: italic 12px/16px ui-monospace, monospace; }
.files { font-size: 13px; }
.stack .divider { display: none; position: absolute; top: -6px; bottom: -6px; width: 1px;
  background: #fff; border: 1px solid #0969da; border-width: 0 1px; pointer-events: none; }
.frame[data-view="slider"] .stack .divider { display: block; }
kbd { border: 1px solid #bbb; border-radius: 3px; padding: 0 4px; background: #fff; }
"""

_JS = r"""
(function () {
  "use strict";
  var frames = Array.prototype.slice.call(document.querySelectorAll(".frame"));
  var current = -1;
  function visible(el) { return el.offsetParent !== null; }
  function showing(f) {
    var s = f.querySelector(".showing");
    if (!s) return;
    var v = f.dataset.view;
    s.textContent = v === "blink" ? (f.classList.contains("show-run") ? "showing: this run"
      : "showing: golden") : "";
  }
  function setView(f, v) {
    if (!f.querySelector(".panel")) return;
    if (v === "blink" && f.dataset.view === "blink") f.classList.toggle("show-run");
    f.dataset.view = v;
    showing(f);
  }
  function slide(f, value) {
    var r = f.querySelector('input[type="range"]');
    if (!r) return;
    r.value = String(value);
    var over = f.querySelector(".stack img.over");
    over.style.clipPath = "inset(0 0 0 " + r.value + "%)";
    // the divider: 3 px (blue, white, blue) centred on the first column of the run
    var divider = f.querySelector(".stack .divider");
    divider.style.left = (Math.round(over.width * Number(r.value) / 100) - 1) + "px";
  }
  document.querySelectorAll("button.unfold").forEach(function (b) {
    var rows = b.closest("table").querySelectorAll("tr.fold-" + b.dataset.fold);
    var text = b.textContent.replace(/ \(show\)$/, "");
    b.addEventListener("click", function () {
      var open = b.dataset.open === "1";
      rows.forEach(function (tr) { tr.hidden = open; });
      b.dataset.open = open ? "0" : "1";
      b.textContent = text + (open ? " (show)" : " (hide)");
    });
  });
  function select(f) {
    if (frames[current]) frames[current].classList.remove("current");
    current = frames.indexOf(f);
    f.classList.add("current");
  }
  frames.forEach(function (f) {
    f.addEventListener("click", function () { select(f); });
    f.querySelectorAll("button[data-view]").forEach(function (b) {
      b.addEventListener("click", function () { setView(f, b.dataset.view); });
    });
    var r = f.querySelector('input[type="range"]');
    if (r) {
      r.addEventListener("input", function () { slide(f, r.value); });
      slide(f, r.value);
    }
  });
  function focusFrame(i) {
    var shown = frames.filter(visible);
    if (!shown.length) return;
    if (frames[current]) frames[current].classList.remove("current");
    var pos = shown.indexOf(frames[current]);
    pos = Math.max(0, Math.min(shown.length - 1, pos + i));
    current = frames.indexOf(shown[pos]);
    var f = frames[current];
    f.classList.add("current");
    f.scrollIntoView({block: "nearest"});
  }
  function jumpFailure(step) {
    var bad = Array.prototype.slice.call(
      document.querySelectorAll('section.scenario:not([data-status="passed"])'));
    if (!bad.length) return;
    var here = frames[current] ? bad.indexOf(frames[current].closest("section")) : -1;
    var next = bad[Math.max(0, Math.min(bad.length - 1, here + step))];
    if (here < 0 && step < 0) next = bad[0];
    var f = next.querySelector(".frame");
    if (frames[current]) frames[current].classList.remove("current");
    if (f) {
      current = frames.indexOf(f);
      f.classList.add("current");
    } else {
      current = -1;
    }
    next.scrollIntoView({block: "start"});
    location.hash = next.id;
  }
  var filter = document.getElementById("only-failures");
  filter.addEventListener("change", function () {
    document.body.classList.toggle("only-failures", filter.checked);
  });
  var keyViews = {"1": "side", "2": "blink", "3": "slider", "4": "diff",
                  "s": "side", "b": "blink", "l": "slider", "d": "diff"};
  document.addEventListener("keydown", function (e) {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.target && e.target.tagName === "INPUT" && e.target.type === "range") return;
    var f = frames[current];
    if (e.key === "j") focusFrame(current < 0 ? 0 : 1);
    else if (e.key === "k") focusFrame(current < 0 ? 0 : -1);
    else if (e.key === "n") jumpFailure(1);
    else if (e.key === "p") jumpFailure(-1);
    else if (e.key === "f") { filter.checked = !filter.checked;
      filter.dispatchEvent(new Event("change")); }
    else if (keyViews[e.key] && f) setView(f, keyViews[e.key]);
    else if ((e.key === "ArrowLeft" || e.key === "ArrowRight") && f &&
             f.dataset.view === "slider") {
      var r = f.querySelector('input[type="range"]');
      slide(f, Math.max(0, Math.min(100, Number(r.value) + (e.key === "ArrowLeft" ? -10 : 10))));
    } else return;
    e.preventDefault();
  });
})();
"""
