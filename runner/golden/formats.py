"""What `collide2d check` prints and files for tools: `--format text|json` and `--junit FILE`.

`--format text` (the default) prints the console story of each scenario and a closing count;
`--format json` prints nothing until the end and then one JSON document on stdout, the same
summary `check --report` keeps in `summary.json` (`report.summary_dict`: counts, the summary line,
per scenario its status, why it changed, the first differing event, problems and frames, and the
scenarios not checked with their errors). `--junit FILE` writes JUnit XML (`junit`), one test case
per scenario (an error case for one not checked), whichever format prints. Under `--format json`
stdout holds that document alone: while the scenarios are read and run, whatever else would print
there (a model plugin's `print`, a write to file descriptor 1) goes to stderr (`stdout_held`).
"""

from __future__ import annotations

import contextlib
import gc
import json
import os
import stat
import sys
from pathlib import Path

from collide2d.runner.golden import report
from collide2d.runner.golden.junit import write_junit
from collide2d.runner.golden.store import GoldenError, link_message

FORMATS = ("text", "json")


def add_check_formats(parser) -> None:
    """`--format` and `--junit` on the `check` parser."""
    parser.add_argument(
        "--format",
        choices=FORMATS,
        default="text",
        help="text for people (default) or one JSON summary on stdout for tools",
    )
    parser.add_argument(
        "--junit", metavar="FILE", help="also write JUnit XML, one test case per scenario"
    )


class Output:
    """The check's stdout and files: `say(text)` prints in text format; `finish(...)` prints the
    JSON summary and writes the JUnit file. The JUnit path is checked when this is made, before
    anything runs (a folder or a symbolic link there is refused with GoldenError)."""

    def __init__(self, args):
        self.json = getattr(args, "format", "text") == "json"
        self.junit = getattr(args, "junit", None)
        if self.junit:
            try:
                st = os.lstat(self.junit)
            except FileNotFoundError:
                st = None
            if st is not None and stat.S_ISLNK(st.st_mode):
                raise GoldenError(link_message(self.junit, "JUnit files"))
            if st is not None and not stat.S_ISREG(st.st_mode):
                raise GoldenError(f"--junit {self.junit} is not a file")
            if not Path(self.junit).parent.is_dir():
                raise GoldenError(f"--junit {self.junit}: no folder {Path(self.junit).parent}")

    def say(self, text: str) -> None:
        if not self.json:
            print(text, flush=True)

    def finish(self, outcomes, unused, errors) -> None:
        """errors: (name, message) of the scenarios that could not be checked. The JSON summary
        is printed before the JUnit file is written, so a file that cannot be written (an
        OSError, raised) leaves the summary whole."""
        if self.json:
            doc = report.summary_dict(outcomes, unused, Path.cwd(), errors)
            json.dump(doc, sys.stdout, indent=2)
            sys.stdout.write("\n")
            sys.stdout.flush()
        if self.junit:
            write_junit(self.junit, outcomes, errors)


@contextlib.contextmanager
def stdout_held():
    """Everything printed to stdout meanwhile goes to stderr: `sys.stdout` and, where it can be,
    file descriptor 1 too (code that writes to it directly, processes started meanwhile). Put
    back after, so that the JSON document alone reaches stdout."""
    before = sys.stdout
    _flush(before, sys.__stdout__)
    saved = None
    try:
        saved = os.dup(1)
        os.dup2(2, 1)
    except OSError:  # no descriptor 1 or 2 (closed): sys.stdout alone is held
        if saved is not None:
            os.close(saved)
            saved = None
    sys.stdout = sys.stderr
    try:
        yield
    finally:
        gc.collect()  # what the runs left in reference cycles goes now, its __del__ held too
        _flush(before, sys.__stdout__, sys.stderr)  # written meanwhile: to stderr still
        if saved is not None:
            os.dup2(saved, 1)
            os.close(saved)
        sys.stdout = before


def _flush(*streams) -> None:
    for stream in streams:
        try:
            stream.flush()
        except (AttributeError, OSError, ValueError):  # none, or closed
            pass
