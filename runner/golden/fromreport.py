"""`collide2d bless --from-report DIR [NAME...]`: accept what a report shows, without running again.

`check --report DIR` keeps, beside each failing scenario's page, the golden its run would bless
(`DIR/NAME/run/`: manifest, events, final state, frames; see `report`). This command writes those
files as the scenario's golden. Each is read back as a golden is (`store`: every file checked
against the manifest's hashes, hostile content refused, no symbolic link followed), and it is
refused when the scenario file, or the table its objects come from, was edited after the report was
written (the manifest's scenario hash differs): the report would no longer show what the scenario
gives. With no NAME, every scenario the report holds a run of and lists as failed (its
`summary.json`) is blessed.
"""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path

from collide2d.runner.command.exitcodes import EXIT_BAD_INPUT, EXIT_OK
from collide2d.runner.golden import report, serialize
from collide2d.runner.golden.session import CREATED, UNCHANGED, UPDATED
from collide2d.runner.golden.store import (
    DEFAULT_MAX_FRAME_PIXELS,
    GoldenError,
    GoldenStore,
    _read_folder,
    link_message,
    shown_path,
)


def add_from_report(parser) -> None:
    """`--from-report DIR` on the `bless` parser."""
    parser.add_argument(
        "--from-report",
        metavar="DIR",
        help="bless what the report in DIR shows (its runs), without running again",
    )


def _error(text: str) -> int:
    print(f"collide2d: error: {text}", file=sys.stderr, flush=True)
    return EXIT_BAD_INPUT


def _is_link(path: Path) -> bool:
    try:
        return stat.S_ISLNK(os.lstat(path).st_mode)
    except FileNotFoundError:
        return False


def runs_in(report_dir: Path) -> list[str]:
    """The names of the scenarios whose run the report keeps, sorted: those its summary.json
    lists as not passed (a folder left by an older report of the same folder is not blessed)."""
    held = {
        p.name
        for p in report_dir.iterdir()
        if not p.is_symlink() and (p / report.RUN_DIR / report.MANIFEST_FILE).is_file()
    }
    summary = report_dir / report.SUMMARY_FILE
    if _is_link(summary) or not summary.is_file():
        return sorted(held)
    try:
        data = serialize.load_json(summary.read_bytes()[: 64 * 1024 * 1024])
        failed = {s["name"] for s in data["scenarios"] if s["status"] != report.STATUS_PASSED}
    except (ValueError, KeyError, TypeError):
        return sorted(held)
    return sorted(held & failed)


def bless_from_report(args, prepare) -> int:
    """Bless from `args.from_report`; `prepare(args)` -> (root, [(path, Scenario)]) loads the
    scenarios named (it raises the CLI's usage error on bad input)."""
    report_dir = Path(args.from_report)
    if _is_link(report_dir):
        return _error(link_message(report_dir, "reports"))
    if not report_dir.is_dir():
        return _error(f"--from-report {args.from_report}: no such folder")
    held = runs_in(report_dir)
    if not args.scenarios:
        if not held:
            return _error(f"{shown_path(report_dir)} holds no run to bless (nothing failed?)")
        args.scenarios = held
    root, scenarios = prepare(args)
    store = GoldenStore(root)
    status = EXIT_OK
    for _path, scn in scenarios:
        try:
            line = _bless_one(report_dir, scn, store)
        except GoldenError as exc:
            status = max(status, _error(f"{scn.name}: {exc}"))
            continue
        print(line, flush=True)
    return status


def _bless_one(report_dir: Path, scn, store: GoldenStore) -> str:
    folder = report_dir / scn.name
    run = folder / report.RUN_DIR
    for path in (folder, run):
        if _is_link(path):
            raise GoldenError(link_message(path, "reports"))
    if not (run / report.MANIFEST_FILE).is_file():
        raise GoldenError(f"{shown_path(report_dir)} holds no run of {scn.name}")
    golden = _read_folder(scn.name, run, DEFAULT_MAX_FRAME_PIXELS)
    if golden.manifest.get("scenario") != scn.name:
        raise GoldenError(f"{shown_path(run)} is a run of {golden.manifest.get('scenario')!r}")
    then, now = golden.manifest.get("scenario_sha256"), getattr(scn, "text_sha256", None)
    if then is None or then != now:
        raise GoldenError(
            "the scenario was edited after the report was written (the hash of its text and any "
            "table differs); run `collide2d check --report` again"
        )
    existed = store.folder(scn.name).exists()
    changed = store.write(scn.name, golden.files)
    verb = UPDATED if changed and existed else CREATED if changed else UNCHANGED
    return f"{verb:<9} {scn.name}: from {shown_path(run)}"
