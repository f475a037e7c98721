"""Golden reports: what a person reads when a check fails — console text, images, JSON, HTML.

Inputs: an `Outcome` per scenario (built by `runner.golden.check_run`), holding the problems found,
the frames that differ (golden and run pixels with their `compare.FrameDiff`) and the golden and run
texts of events and final state when those differ. Outputs:

- `Outcome.message()`: the console text — the scenario, the first differing event and every
  differing frame (pixels, bounding box, image paths), the report and the exact command to bless;
- `write_scenario(DIR, outcome)`: `DIR/NAME/` with `frame_000006_expected.png`, `_actual.png` and
  `_diff.png` per differing frame (the diff: differing pixels in magenta, pixels changed within the
  colour threshold in amber, over the run's frame dimmed to grey), the golden and run event logs or
  final states when they differ, `summary.json` and a self-contained `index.html`;
- `write_index(DIR, outcomes, unused)`: `DIR/summary.json` and `DIR/index.html` over all scenarios.

Pages reference their images by relative paths and load nothing from the network, so a report
folder can be zipped, kept as a CI artifact and opened anywhere. A report is written only into real
folders: a report folder, scenario folder or file that is a symbolic link is refused
(`ReportRefused`, naming it), never followed or replaced, and nothing in a report folder is deleted.
"""

from __future__ import annotations

import html
import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from collide2d.runner.golden.compare import FrameDiff
from collide2d.runner.golden.store import GoldenError, link_message, shown_path
from collide2d.runner.outputs import atomic_write_bytes, encode_png, write_json

REPORT_FORMAT = 1
# Diff image colours (RGB) and how bright the grey copy of the frame under them is (0..1).
DIFF_COLOR = (255, 0, 255)
WITHIN_THRESHOLD_COLOR = (255, 176, 0)
DIM_LEVEL = 0.35
# On the pages, frames narrower than this many pixels are shown at twice their size.
ZOOM_BELOW_PX = 480

STATUS_PASSED = "passed"
STATUS_FAILED = "failed"
STATUS_MISSING = "missing"
STATUS_UNREADABLE = "unreadable"
INDEX_FILE = "index.html"
SUMMARY_FILE = "summary.json"


class ReportRefused(GoldenError):
    """A report cannot be written where asked (a symbolic link stands in the way)."""


def _refuse_link(path: Path) -> None:
    try:
        st = os.lstat(path)
    except (FileNotFoundError, NotADirectoryError):
        return
    if stat.S_ISLNK(st.st_mode):
        raise ReportRefused(link_message(path, "reports"))


def check_target(report_dir, names=()) -> None:
    """ReportRefused when the report folder, a scenario folder `names` would use in it, or a file
    the report writes at its top is a symbolic link; checked before anything runs."""
    folder = Path(report_dir)
    _refuse_link(folder)
    for entry in (SUMMARY_FILE, INDEX_FILE, *names):
        _refuse_link(folder / entry)


def _write(path: Path, data: bytes) -> None:
    """Write a report file, refusing a link in its place."""
    _refuse_link(path)
    atomic_write_bytes(path, data)


def _real_folder(folder: Path) -> Path:
    """Make `folder` (and its parents) and check that it is a real folder, not a link."""
    _refuse_link(folder)
    folder.mkdir(parents=True, exist_ok=True)
    _refuse_link(folder)
    return folder


@dataclass
class FrameReport:
    """A frame that differs: `diff` is None when only one side has the frame (expected or actual
    None). `paths` maps expected / actual / diff to the files written, once written."""

    frame: int
    message: str
    expected: np.ndarray | None
    actual: np.ndarray | None
    diff: FrameDiff | None = None
    paths: dict = field(default_factory=dict)


@dataclass
class Outcome:
    """What checking one scenario found.

    name, scenario: the scenario's name and its file as shown to the user; bless: the command that
    accepts the run; problems: in order (golden, events, frames, final state), a message per
    difference, a `FrameReport` for a frame; texts: report file name -> bytes (golden and run event
    logs or final states that differ); report: the scenario's index.html once written.
    """

    name: str
    scenario: str
    bless: str
    status: str = STATUS_PASSED
    problems: list = field(default_factory=list)
    texts: dict = field(default_factory=dict)
    report: Path | None = None

    @property
    def ok(self) -> bool:
        return self.status == STATUS_PASSED

    @property
    def frames(self) -> list:
        """The FrameReports among the problems."""
        return [p for p in self.problems if isinstance(p, FrameReport)]

    def message(self) -> str:
        """The console text of this outcome: one line when it passed, the full story when not."""
        if self.ok:
            return f"ok      {self.name}"
        lines = [f"{self.status.upper():<7} {self.name} ({self.scenario})"]
        for problem in self.problems:
            text = problem.message if isinstance(problem, FrameReport) else problem
            lines.extend("  " + line for line in text.splitlines())
            if isinstance(problem, FrameReport):
                for kind in ("expected", "actual", "diff"):
                    if kind in problem.paths:
                        lines.append(f"    {kind + ':':<9} {shown_path(problem.paths[kind])}")
        if self.report is not None:
            lines.append(f"  report: {shown_path(self.report)}")
        elif self.status == STATUS_FAILED:
            lines.append("  (pass --report DIR for expected / actual / diff images)")
        verb = "create it" if self.status == STATUS_MISSING else "accept this run as the golden"
        lines.append(f"  to {verb}: {self.bless}")
        return "\n".join(lines)

    def summary(self, base: Path | None = None) -> dict:
        """A JSON-ready record of this outcome; paths relative to `base` when given."""
        folder = Path(self.report).parent if self.report is not None else None
        return {
            "name": self.name,
            "scenario": self.scenario,
            "status": self.status,
            "problems": [p.message if isinstance(p, FrameReport) else p for p in self.problems],
            "frames": [_frame_summary(f, base) for f in self.frames],
            "files": [_rel(folder / k, base) for k in sorted(self.texts)] if folder else [],
            "report": _rel(self.report, base) if self.report is not None else None,
            "bless": self.bless,
        }


def _frame_summary(fr: FrameReport, base: Path | None) -> dict:
    d = {"frame": fr.frame, "message": fr.message}
    if fr.diff is not None:
        d.update(
            expected_size=list(fr.diff.expected_size),
            actual_size=list(fr.diff.actual_size),
            n_diff=fr.diff.n_diff,
            bbox=list(fr.diff.bbox) if fr.diff.bbox is not None else None,
        )
    d.update({k: _rel(p, base) for k, p in sorted(fr.paths.items())})
    return d


def diff_image(fr: FrameReport) -> np.ndarray | None:
    """(H, W, 3) uint8: the run's frame in dim grey (its brightest channel times DIM_LEVEL),
    pixels changed within the colour threshold in WITHIN_THRESHOLD_COLOR, differing pixels in
    DIFF_COLOR. None when there is nothing to overlay (sizes differ or one side is missing)."""
    d = fr.diff
    if d is None or d.size_mismatch or d.mask is None:
        return None
    grey = fr.actual.max(axis=2).astype(np.float64) * DIM_LEVEL
    out = np.repeat(grey.astype(np.uint8)[:, :, None], 3, axis=2)
    out[d.changed & ~d.mask] = WITHIN_THRESHOLD_COLOR
    out[d.mask] = DIFF_COLOR
    return out


def write_scenario(report_dir, outcome: Outcome) -> Path:
    """Write `report_dir/NAME/` for a failed outcome (images, texts, summary.json, index.html);
    sets `outcome.report` and each frame's `paths`; returns the index.html path."""
    _refuse_link(Path(report_dir))
    folder = _real_folder(Path(report_dir) / outcome.name)
    for fr in outcome.frames:
        stem = f"frame_{fr.frame:06d}"
        images = {"expected": fr.expected, "actual": fr.actual, "diff": diff_image(fr)}
        for kind, rgb in images.items():
            if rgb is not None:
                path = folder / f"{stem}_{kind}.png"
                _write(path, encode_png(np.ascontiguousarray(rgb)))
                fr.paths[kind] = path
    for fname, data in sorted(outcome.texts.items()):
        _write(folder / fname, data)
    outcome.report = folder / INDEX_FILE
    _refuse_link(folder / SUMMARY_FILE)
    write_json(folder / SUMMARY_FILE, outcome.summary(folder))
    page = _page(f"collide2d golden: {outcome.name}", [outcome], folder, [])
    _write(outcome.report, page)
    return outcome.report


def write_index(report_dir, outcomes, unused=()) -> Path:
    """Write `report_dir/summary.json` and `report_dir/index.html` over `outcomes` (sorted by
    name) and the unused goldens; returns the index.html path."""
    folder = _real_folder(Path(report_dir))
    outcomes = sorted(outcomes, key=lambda o: o.name)
    summary = {
        "format": REPORT_FORMAT,
        "passed": sum(o.ok for o in outcomes),
        "failed": sum(not o.ok for o in outcomes),
        "scenarios": [o.summary(folder) for o in outcomes],
        "unused_goldens": list(unused),
    }
    _refuse_link(folder / SUMMARY_FILE)
    write_json(folder / SUMMARY_FILE, summary)
    index = folder / INDEX_FILE
    _write(index, _page("collide2d golden check", outcomes, folder, list(unused)))
    return index


def _rel(path, base: Path | None) -> str:
    if base is None:
        return Path(path).as_posix()
    return Path(os.path.relpath(path, base)).as_posix()


_CSS = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; background: #fafafa; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 2em; }
.passed { color: #1a7f37; } .failed, .missing, .unreadable { color: #cf222e; }
pre { background: #fff; border: 1px solid #ddd; padding: .6em; overflow-x: auto; }
.frame { background: #fff; border: 1px solid #ddd; padding: .8em; margin: 1em 0; }
.views input { display: none; }
.views label { border: 1px solid #bbb; padding: .2em .7em; cursor: pointer; margin-right: .3em; }
.views input:checked + label { background: #222; color: #fff; }
.panel { display: none; margin-top: .8em; }
.views input.side:checked ~ .side-panel, .views input.diff:checked ~ .diff-panel {
  display: flex; flex-wrap: wrap; gap: .8em; }
figure { margin: 0; } figcaption { font-size: .85em; color: #555; }
img { image-rendering: pixelated; border: 1px solid #999; background: #000; }
"""


def _page(title: str, outcomes, folder: Path, unused: list) -> bytes:
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    if len(outcomes) > 1 or unused:
        parts.append("<ul>")
        for o in outcomes:
            parts.append(
                f'<li><a href="#{html.escape(o.name)}">{html.escape(o.name)}</a> '
                f'<span class="{o.status}">{o.status}</span></li>'
            )
        parts.append("</ul>")
    if unused:
        names = ", ".join(html.escape(n) for n in unused)
        parts.append(
            f"<p>Goldens no scenario uses: {names} "
            "(remove them with <code>collide2d bless --prune</code>).</p>"
        )
    for o in outcomes:
        parts.append(_section(o, folder))
    parts.append("</body></html>\n")
    return "\n".join(parts).encode("utf-8")


def _section(o: Outcome, folder: Path) -> str:
    name = html.escape(o.name)
    out = [
        f'<h2 id="{name}">{name} <span class="{o.status}">{o.status}</span></h2>',
        f"<p>Scenario <code>{html.escape(o.scenario)}</code>.</p>",
    ]
    if o.ok:
        return "\n".join(out)
    texts = [p for p in o.problems if not isinstance(p, FrameReport)]
    if texts:
        out.append("<pre>" + html.escape("\n".join(texts)) + "</pre>")
    if o.report is not None and o.texts:
        links = ", ".join(
            f'<a href="{html.escape(_rel(Path(o.report).parent / k, folder))}">{html.escape(k)}</a>'
            for k in sorted(o.texts)
        )
        out.append(f"<p>Golden and run side by side as text: {links}</p>")
    for fr in o.frames:
        out.append(_frame_block(o.name, fr, folder))
    out.append(f"<p>To accept this run: <code>{html.escape(o.bless)}</code></p>")
    return "\n".join(out)


def _frame_block(name: str, fr: FrameReport, folder: Path) -> str:
    key = html.escape(f"{name}-{fr.frame}")
    figures = []
    for kind in ("expected", "actual", "diff"):
        if kind in fr.paths:
            figures.append(_figure(kind, fr, folder))
    side = "".join(figures)
    diff = _figure("diff", fr, folder) if "diff" in fr.paths else "<p>No diff image.</p>"
    return (
        f'<div class="frame"><p>{html.escape(fr.message)}</p><div class="views">'
        f'<input type="radio" class="side" name="v-{key}" id="s-{key}" checked>'
        f'<label for="s-{key}">side by side</label>'
        f'<input type="radio" class="diff" name="v-{key}" id="d-{key}">'
        f'<label for="d-{key}">diff</label>'
        f'<div class="panel side-panel">{side}</div>'
        f'<div class="panel diff-panel">{diff}</div></div></div>'
    )


def _figure(kind: str, fr: FrameReport, folder: Path) -> str:
    rgb = {"expected": fr.expected, "actual": fr.actual}.get(kind)
    if rgb is None:
        rgb = fr.actual if fr.actual is not None else fr.expected
    h, w = rgb.shape[:2]
    zoom = 2 if w < ZOOM_BELOW_PX else 1
    src = html.escape(_rel(fr.paths[kind], folder))
    caption = {"expected": "golden", "actual": "this run", "diff": "diff"}[kind]
    return (
        f'<figure><img src="{src}" width="{w * zoom}" height="{h * zoom}" alt="{kind}">'
        f"<figcaption>{caption} ({w}x{h})</figcaption></figure>"
    )
