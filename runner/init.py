"""The `init` command: make a folder a collide2d project, ready for `pytest` and CI.

`collide2d init [DIR]` (default: the current folder) writes `scenarios/example.yaml` (a commented
scenario showing every section; kept if it exists), a `[tool.collide2d]` table in
`pyproject.toml` (the file created, or the table appended to it; a file that already has the table
is left alone), and an `out/` line in `.gitignore`, then prints the next three commands. Nothing
is overwritten: each step says whether it created, extended or kept its file. A `pyproject.toml`
that is not valid TOML is refused (`FILE:LINE:COL: error: ...`, exit 2) before anything is written.
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from collide2d.runner.exitcodes import EXIT_OK

EXAMPLE = "example.yaml"
TABLE_TEXT = """[tool.collide2d]
# collide2d's settings for this project (`collide2d config` prints them with their sources);
# the command line wins over a scenario file, which wins over this table.
scenarios = "scenarios"   # scenario files: one golden test each under plain `pytest`
goldens = "goldens"       # what `pytest --update-goldens` and `collide2d bless` write
report = "report"         # `collide2d check --report` writes its HTML report here
out = "out"               # `collide2d run` writes OUT/NAME/ here

# [tool.collide2d.limits]  # raise or lower the limits of a run (the --max-* options)
# max_objects = 5000
# max_ticks = 100000

# [tool.collide2d.model]   # model settings for scenarios that give none
# kind = "stepped"
# substeps = 8
# geometry = "exact"
"""
IGNORE = "out/"
NEXT = (
    ("collide2d run scenarios/example.yaml", "see it: out/example/animation.gif"),
    ("pytest --update-goldens", "record its golden in goldens/ (commit that folder)"),
    ("pytest", "compare with the golden, as CI will (or: collide2d check)"),
)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "init",
        help="make a folder a collide2d project: scenarios/, [tool.collide2d], .gitignore",
        description="Write scenarios/example.yaml, a [tool.collide2d] table in pyproject.toml "
        "and an out/ line in .gitignore into DIR (default: here); existing files are kept or "
        "extended, never overwritten.",
    )
    p.add_argument("dir", nargs="?", default=".", metavar="DIR", help="project folder")
    p.set_defaults(func=run_init)


def run_init(args: argparse.Namespace) -> int:
    for line in init(Path(args.dir)):
        print(line)
    print("next:" if args.dir in (".", "") else f"next, in {args.dir}:")
    width = max(len(c) for c, _ in NEXT)
    for command, why in NEXT:
        print(f"  {command:<{width}}  # {why}")
    return EXIT_OK


def init(root: Path) -> list[str]:
    """Make `root` a project; returns one line per file: what was done to it."""
    from collide2d.runner import config

    pyproject = root / config.PYPROJECT
    if pyproject.is_file():
        has = config.has_table(pyproject)
        config._table(pyproject)  # refuse a file that is not TOML before writing anything
    else:
        has = False
    root.mkdir(parents=True, exist_ok=True)
    said = []
    example = root / "scenarios" / EXAMPLE
    example.parent.mkdir(exist_ok=True)
    try:
        with open(example, "x", encoding="utf-8") as f:
            f.write((resources.files("collide2d.runner") / "data" / EXAMPLE).read_text("utf-8"))
        said.append(f"created   {example}")
    except FileExistsError:
        said.append(f"kept      {example} (it exists)")
    if has:
        said.append(f"kept      {pyproject} (it has a [tool.collide2d] table)")
    else:
        said.append(_append(pyproject, TABLE_TEXT, blank_line=True))
    gitignore = root / ".gitignore"
    lines = gitignore.read_text(encoding="utf-8").splitlines() if gitignore.is_file() else []
    if IGNORE in lines or IGNORE.rstrip("/") in lines or "/" + IGNORE in lines:
        said.append(f"kept      {gitignore} (it ignores {IGNORE})")
    else:
        said.append(_append(gitignore, IGNORE + "\n"))
    return said


def _append(path: Path, text: str, blank_line: bool = False) -> str:
    """Append `text` to `path` (created if missing) from a line of its own (after a blank line
    with `blank_line`); the line to print."""
    if path.is_file():
        old = path.read_text(encoding="utf-8")
        sep = "" if not old or old.endswith("\n") else "\n"
        if blank_line and old and not (old + sep).endswith("\n\n"):
            sep += "\n"
        with open(path, "a", encoding="utf-8") as f:
            f.write(sep + text)
        return f"extended  {path}"
    path.write_text(text, encoding="utf-8")
    return f"created   {path}"
