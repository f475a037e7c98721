"""Checking and blessing one scenario: the four roles of the golden harness joined together.

`serialize`, `store`, `compare` and `report` each do one role (see the package's docstring); this
module joins them for one scenario, and `cli` (the `check` and `bless` commands) and `plugin`
(pytest) drive it.

Inputs: a Scenario (`runner.scenario.load`), its RunResult (`runner.run.simulate` with the
scenario's golden frames kept) and a `GoldenStore`. Outputs: `check_run` -> a `report.Outcome`
(passed, failed, missing or unreadable, with every difference found); `bless_run` -> a `Blessed`
record (created, updated or unchanged, with a one-line summary of what changed).
"""

from __future__ import annotations

import json
import shlex
from dataclasses import dataclass

from collide2d.runner.golden import compare, report, serialize, why
from collide2d.runner.golden.store import (
    DEFAULT_MAX_FRAME_PIXELS,
    GoldenMissing,
    GoldenStore,
    GoldenUnreadable,
    shown_path,
)

CREATED = "created"
UPDATED = "updated"
UNCHANGED = "unchanged"


def bless_command(path) -> str:
    """The exact command that blesses the scenario file `path`."""
    return f"collide2d bless {shlex.quote(shown_path(path))}"


def golden_frames(scenario) -> list[int]:
    """The scenario's golden frame numbers, sorted and unique."""
    return sorted({int(k) for k in scenario.golden.frames})


def frame_pixel_bound(frames: dict) -> int:
    """The most pixels a golden frame may claim before it is decoded: the run's largest frame, or
    `store.DEFAULT_MAX_FRAME_PIXELS` when that is more (memory stays within what the run used)."""
    sizes = [int(rgb.shape[0]) * int(rgb.shape[1]) for rgb in frames.values()]
    return max([DEFAULT_MAX_FRAME_PIXELS, *sizes])


def check_run(scenario, result, store: GoldenStore, *, path=None, report_dir=None, viewer=None):
    """Compare `result` (a RunResult of `scenario`) with the scenario's golden in `store`.

    path: the scenario file (default scenario.path), used in messages and the bless command;
    report_dir: when given and the check fails, write `report_dir/NAME/` (see `report`);
    viewer: with a report, `viewer(scenario, golden frames)` -> the bytes of the run's viewer.html
    or None (`replay.viewer_page`, which runs the scenario again). Returns a report.Outcome.
    """
    path = path if path is not None else (scenario.path or f"{scenario.name}.yaml")
    outcome = report.Outcome(scenario.name, shown_path(path), bless_command(path))
    outcome.names = tuple(getattr(scenario, "names", ()))
    run_frames = {k: result.frames[k] for k in golden_frames(scenario) if k in result.frames}
    try:
        golden = store.read(scenario.name, max_frame_pixels=frame_pixel_bound(run_frames))
    except GoldenMissing as exc:
        outcome.status = report.STATUS_MISSING
        outcome.problems.append(str(exc))
        if report_dir is not None:  # show what a bless would write
            outcome.problems.extend(
                report.FrameReport(k, f"frame {k}: no golden yet (this run's frame)", None, rgb)
                for k, rgb in sorted(run_frames.items())
            )
    except GoldenUnreadable as exc:
        outcome.status = report.STATUS_UNREADABLE
        outcome.problems.append(str(exc))
    else:
        _compare(scenario, result, golden, run_frames, outcome)
        if outcome.problems:
            outcome.status = report.STATUS_FAILED
            outcome.problems[:0] = _setting_notes(scenario, golden.manifest)
            outcome.cause = why.cause(scenario, golden.manifest)
    if report_dir is not None and not outcome.ok:
        if outcome.status != report.STATUS_UNREADABLE or run_frames:
            outcome.run_files = _run_files(scenario, result)
        if viewer is not None:
            ghost = golden.frames if outcome.status == report.STATUS_FAILED else {}
            outcome.viewer = viewer(scenario, ghost)
        report.write_scenario(report_dir, outcome)
    return outcome


def _run_files(scenario, result) -> dict:
    """The golden files this run would bless (kept in a report for `bless --from-report`); empty
    when the run lacks a golden frame."""
    try:
        return golden_files(scenario, result)
    except ValueError:
        return {}


def _setting_notes(scenario, manifest) -> list[str]:
    """Notes on what the scenario changed since its golden was blessed (model, world, ticks)."""
    now = serialize.manifest(scenario, b"", b"", {})
    return [
        f"note: the golden was blessed with {key} {json.dumps(manifest.get(key))}, "
        f"the scenario now has {json.dumps(now[key])}"
        for key in ("model", "world", "ticks")
        if manifest.get(key) != now[key]
    ]


def _compare(scenario, result, golden, run_frames, outcome) -> None:
    g = scenario.golden
    tol = float(g.time_tolerance)
    events = serialize.event_dicts(result.events)
    mismatch = compare.compare_events(golden.events, events, tol)
    if mismatch is not None:
        outcome.problems.append(mismatch.message())
        outcome.first_event = mismatch.index
        outcome.texts["events_expected.jsonl"] = golden.files[serialize.EVENTS_FILE]
        outcome.texts["events_actual.jsonl"] = serialize.events_jsonl(result.events)
    hashes = {int(e["frame"]): e["pixels_sha256"] for e in golden.manifest["frames"]}
    for k in sorted(set(golden.frames) | set(golden_frames(scenario))):
        exp, act = golden.frames.get(k), run_frames.get(k)
        if exp is None:
            msg = f"frame {k}: not in the golden (its frames are {sorted(golden.frames)})"
            outcome.problems.append(report.FrameReport(k, msg, None, act))
            continue
        if act is None:
            if k in g.frames:
                msg = f"frame {k}: in the golden, but this run produced no frame {k}"
            else:
                msg = f"frame {k}: in the golden, but no longer among the scenario's golden frames"
            outcome.problems.append(report.FrameReport(k, msg, exp, None))
            continue
        diff = compare.compare_frame(
            k,
            exp,
            act,
            color_threshold=g.color_threshold,
            max_diff_pixels=g.max_diff_pixels,
            expected_sha256=hashes.get(k),
        )
        if not diff.passed:
            outcome.problems.append(report.FrameReport(k, diff.message(), exp, act, diff))
    final = serialize.final_state(result.final_pos, result.final_vel)
    fm = compare.compare_final(golden.final, final, tol)
    if fm is not None:
        outcome.problems.append(fm.message())
        outcome.texts["final_expected.csv"] = golden.files[serialize.FINAL_FILE]
        outcome.texts["final_actual.csv"] = serialize.final_csv(result.final_pos, result.final_vel)


@dataclass(frozen=True)
class Blessed:
    """What blessing one scenario did: status is created / updated / unchanged; summary says what
    changed in one line; files are the golden files rewritten (relative paths)."""

    name: str
    status: str
    summary: str
    files: tuple

    def line(self) -> str:
        return f"{self.status:<9} {self.name}: {self.summary}"


def golden_files(scenario, result, old=None) -> dict:
    """The files of the golden for `result`: relative path -> bytes. A frame whose pixels equal
    the old golden's keeps its old PNG bytes, so re-blessing never churns PNGs over encoder
    differences."""
    frames = {k: result.frames[k] for k in golden_frames(scenario) if k in result.frames}
    missing = [k for k in golden_frames(scenario) if k not in result.frames]
    if missing:
        raise ValueError(f"the run of {scenario.name} did not keep golden frames {missing}")
    events = serialize.events_jsonl(result.events)
    final = serialize.final_csv(result.final_pos, result.final_vel)
    manifest = serialize.manifest(scenario, events, final, frames)
    files = {serialize.EVENTS_FILE: events, serialize.FINAL_FILE: final}
    old_hashes = {}
    if old is not None:
        old_hashes = {e["file"]: e["pixels_sha256"] for e in old.manifest["frames"]}
    for entry in manifest["frames"]:
        rel = entry["file"]
        same = old_hashes.get(rel) == entry["pixels_sha256"]
        files[rel] = old.files[rel] if same else serialize.png_bytes(frames[entry["frame"]])
    files[serialize.MANIFEST_FILE] = serialize.manifest_bytes(manifest)
    return files


def bless_run(scenario, result, store: GoldenStore) -> Blessed:
    """Write the golden of `scenario` from `result` (the folder swapped in whole, see `store`);
    say what changed. Raises store.GoldenError when a symbolic link stands in the way."""
    old, note = None, ""
    try:
        old = store.read(scenario.name, max_frame_pixels=frame_pixel_bound(result.frames))
    except GoldenMissing:
        pass
    except GoldenUnreadable as exc:
        note = f"replaced an unreadable golden ({exc})"
    files = golden_files(scenario, result, old)
    changed = tuple(store.write(scenario.name, files))
    if old is None and not note:
        status = CREATED
        summary = _contents(result, files)
    elif not changed:
        status, summary = UNCHANGED, "no change"
    else:
        status = UPDATED
        summary = note or _changes(scenario, result, old, changed)
    return Blessed(scenario.name, status, summary, changed)


def _contents(result, files) -> str:
    n_frames = sum(1 for rel in files if rel.startswith(serialize.FRAMES_DIR + "/"))
    n_obj = serialize.final_state(result.final_pos, result.final_vel).shape[0]
    counts = ((len(result.events), "event"), (n_frames, "frame"), (n_obj, "object"))
    return ", ".join(f"{n} {word}{'' if n == 1 else 's'}" for n, word in counts)


def _changes(scenario, result, old, changed) -> str:
    """One line naming what differs between the old golden and `result`, exactly."""
    parts = []
    events = serialize.event_dicts(result.events)
    em = compare.compare_events(old.events, events, 0.0)
    if em is not None:
        ref = em.expected if em.expected is not None else em.actual
        parts.append(
            f"events from #{em.index + 1} ({compare.event_label(ref)}; "
            f"{len(old.events)} -> {len(events)} events)"
        )
    frames = {k: result.frames[k] for k in golden_frames(scenario)}
    added = sorted(set(frames) - set(old.frames))
    removed = sorted(set(old.frames) - set(frames))
    redrawn = []
    for k in sorted(set(frames) & set(old.frames)):
        d = compare.compare_frame(k, old.frames[k], frames[k])
        if d.size_mismatch:
            (we, he), (wa, ha) = d.expected_size, d.actual_size
            redrawn.append(f"{k} ({we}x{he} -> {wa}x{ha})")
        elif not d.passed:
            redrawn.append(f"{k} ({d.n_diff} px)")
    if redrawn:
        parts.append("frames " + ", ".join(redrawn))
    if added:
        parts.append("frames added " + ", ".join(map(str, added)))
    if removed:
        parts.append("frames removed " + ", ".join(map(str, removed)))
    final = serialize.final_state(result.final_pos, result.final_vel)
    fm = compare.compare_final(old.final, final, 0.0)
    if fm is not None:
        if fm.n_expected != fm.n_actual:
            parts.append(f"final state ({fm.n_expected} -> {fm.n_actual} objects)")
        else:
            parts.append(f"final state ({fm.count} values)")
    if not parts:
        parts.append("rewrote " + ", ".join(changed))
    return "; ".join(parts)
