"""Golden reports: what a person reads when a check fails — console text, images, JSON, HTML.

Inputs: an `Outcome` per scenario (built by `runner.golden.check_run`), holding the problems found,
the frames that differ (golden and run pixels with their `compare.FrameDiff`) and the golden and run
texts of events and final state when those differ. Outputs:

- `Outcome.message()`: the console text — the scenario, the first differing event and every
  differing frame (pixels, bounding box, image paths), the report and the exact command to bless;
- `write_scenario(DIR, outcome)`: `DIR/NAME/` with `frame_000006_expected.png`, `_actual.png` and
  `_diff.png` per differing frame (the diff: differing pixels in magenta, pixels changed within the
  colour threshold in amber, over the run's frame dimmed to grey), the golden and run event logs or
  final states when they differ, `summary.json`, a self-contained `index.html` (see
  `page`; it links the files beside it), `viewer.html`, a viewer of the run with the golden's
  frames as its ghost (when the session made one), and `run/`, the golden files this run would
  bless (`bless --from-report`);
- `write_index(DIR, outcomes, unused)`: `DIR/summary.json` and `DIR/index.html` over all scenarios.

Pages hold their images inline and load nothing from the network, so a page can be mailed, a report
folder zipped, kept as a CI artifact and opened anywhere. A report is written only into real
folders: a report folder, scenario folder or file that is a symbolic link is refused
(`ReportRefused`, naming it), never followed or replaced, and nothing in a report folder is deleted.
"""

from __future__ import annotations

import os
import stat
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from collide2d.runner.golden import page
from collide2d.runner.golden.compare import FrameDiff
from collide2d.runner.golden.store import GoldenError, link_message, shown_path
from collide2d.runner.output.files import atomic_write_bytes, encode_png, write_json

REPORT_FORMAT = 1
# Diff image colours (RGB) and how bright the grey copy of the frame under them is (0..1).
# In a scenario's report folder: the golden files of the run checked (what a bless would write).
RUN_DIR = "run"
MANIFEST_FILE = "manifest.json"

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
    cause: object = None  # why.Cause of a failure: scenario edited or engine changed
    first_event: int | None = None  # index of the first differing event
    run_files: dict = field(default_factory=dict)  # the golden files of this run, for bless
    names: tuple = ()  # the scenario's object names (None for an object without one)
    viewer: bytes | None = None  # viewer.html of this run, with the golden as its ghost

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
        if self.cause is not None:
            lines.append(f"  why: {self.cause.text}")
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
            "cause": self.cause.as_dict() if self.cause is not None else None,
            "first_event": self.first_event,
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


def write_scenario(report_dir, outcome: Outcome) -> Path:
    """Write `report_dir/NAME/` for a failed outcome (images, texts, summary.json, index.html);
    sets `outcome.report` and each frame's `paths`; returns the index.html path."""
    _refuse_link(Path(report_dir))
    folder = _real_folder(Path(report_dir) / outcome.name)
    for fr in outcome.frames:
        stem = f"frame_{fr.frame:06d}"
        images = {"expected": fr.expected, "actual": fr.actual, "diff": page.diff_image(fr)}
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
    if outcome.run_files:
        _write_run_files(folder / RUN_DIR, outcome.run_files)
    if outcome.viewer is not None:
        _write(folder / page.VIEWER, outcome.viewer)
    title = f"collide2d golden: {outcome.name}"
    _write(outcome.report, page.page(title, [outcome], base=folder))
    return outcome.report


def _write_run_files(folder: Path, files: dict) -> None:
    """The golden this run would bless, under the report's NAME/run/ (manifest last)."""
    _real_folder(folder)
    for rel in sorted(files, key=lambda r: (r == MANIFEST_FILE, r)):
        path = folder / rel
        _real_folder(path.parent)
        _write(path, files[rel])


def summary_dict(outcomes, unused=(), base: Path | None = None, errors=()) -> dict:
    """The summary of a check for tools (summary.json, `check --format json`): the counts, the
    summary line, one record per scenario (by name) and the unused goldens; `errors`, (name,
    message) of the scenarios an unexpected error or a refusal kept from being checked (a file
    that could not be read is named by its path), gives `not_checked` (their names) and `errors`
    (one record each: name and message)."""
    outcomes = sorted(outcomes, key=lambda o: o.name)
    out = {
        "format": REPORT_FORMAT,
        "summary": page.summary_line(outcomes),
        "passed": sum(o.ok for o in outcomes),
        "failed": sum(not o.ok for o in outcomes),
        "scenarios": [o.summary(base) for o in outcomes],
        "unused_goldens": list(unused),
    }
    if errors:
        errors = sorted(errors)
        out["not_checked"] = [name for name, _message in errors]
        out["errors"] = [{"name": name, "message": message} for name, message in errors]
    return out


def first_divergence(outcome) -> str:
    """The first line of the first problem that is not a note on the scenario's settings."""
    for problem in outcome.problems:
        text = problem.message if isinstance(problem, FrameReport) else problem
        if not text.startswith("note:"):
            return text.splitlines()[0] if text else text
    return outcome.status


def write_index(report_dir, outcomes, unused=(), errors=()) -> Path:
    """Write `report_dir/summary.json` and `report_dir/index.html` over `outcomes` (sorted by
    name), the unused goldens and the scenarios not checked (`errors`, see `summary_dict`);
    returns the index.html path."""
    folder = _real_folder(Path(report_dir))
    outcomes = sorted(outcomes, key=lambda o: o.name)
    summary = summary_dict(outcomes, unused, folder, errors)
    _refuse_link(folder / SUMMARY_FILE)
    write_json(folder / SUMMARY_FILE, summary)
    index = folder / INDEX_FILE
    _write(index, page.page("collide2d golden check", outcomes, list(unused), base=folder))
    return index


def _rel(path, base: Path | None) -> str:
    if base is None:
        return Path(path).as_posix()
    return Path(os.path.relpath(path, base)).as_posix()
