"""The `init` command: make a folder a collide2d project, ready for `pytest` and CI.

`collide2d init [DIR]` (default: the current folder) writes `scenarios/example.yaml` (a commented
scenario showing every section; kept if it exists), a `[tool.collide2d]` table in
`pyproject.toml` (the file created, or the table appended to it; a file that already has the table
is left alone), and `out/` and `report/` lines in `.gitignore` (what `run` and `check --report`
write; each added unless the file ignores it already), then prints the next three commands. Nothing
is overwritten: each step says whether it created, extended or kept its file.

A pyproject.toml is read as TOML readers read it (its bytes as UTF-8, line ends untouched) and is
extended only when the result says exactly what the file said plus the table, in the file's own line
ends. What cannot be extended so is refused (`FILE:LINE:COL: error: ...`, exit 2): a file that is
not valid TOML, one with a byte order mark, UTF-16 or not UTF-8, and a `tool` that is an inline
table, an array of tables or a value. Refused too (`FILE: error: ...`): a file reached through a
symbolic link (of the file or of a folder on its way) that leads outside the project folder (one
that stays inside is written at the link's target, the link kept), and a folder, FIFO or device in
place of a file (never opened). Every refusal comes before anything is written, and the files are
written all or nothing (`runner.output.filebatch`): when one cannot be written (a full disk), none
is changed and the error names it (exit 2).
"""

from __future__ import annotations

import argparse
import codecs
import os
import re
import stat
from importlib import resources
from pathlib import Path

from collide2d.runner.command.exitcodes import EXIT_OK
from collide2d.runner.output.filebatch import FileBatch
from collide2d.runner.scenario.parse import OptionError

EXAMPLE = "example.yaml"


class InitRefused(OptionError):
    """A file init will not change (a link leading outside the project, an encoding it cannot
    extend): str(err) is `PATH: error: MESSAGE`; nothing is written."""


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
IGNORES = ("out/", "report/")  # the folders of run's outputs and check's report
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
    """Make `root` a project; returns one line per file: what was done to it. Every file is read
    and every refusal made before anything is written, and the writes are all or nothing."""
    from collide2d.runner.command import settings

    project = root.resolve()
    batch = FileBatch()
    said = []
    example = root / "scenarios" / EXAMPLE
    if os.path.lexists(example):
        said.append(f"kept      {example} (it exists)")
    else:
        data = (resources.files("collide2d.runner") / "data" / EXAMPLE).read_bytes()
        batch.add(_target(example, project), data, None)
        said.append(f"created   {example}")
    pyproject = root / settings.PYPROJECT
    old = _read(pyproject)
    if old is None:
        batch.add(_target(pyproject, project), TABLE_TEXT.encode("utf-8"), None)
        said.append(f"created   {pyproject}")
    else:
        text = _toml_text(pyproject, old)
        data = settings.parse(text, pyproject)
        tool = data.get("tool")
        if isinstance(tool, dict) and "collide2d" in tool:
            settings._table(pyproject)  # refuse a [tool.collide2d] that is not a table
            said.append(f"kept      {pyproject} (it has a [tool.collide2d] table)")
        else:
            new = _with_table(pyproject, text, data).encode("utf-8")
            batch.add(_target(pyproject, project), new, old)
            said.append(f"extended  {pyproject}")
    gitignore = root / ".gitignore"
    old = _read(gitignore)
    lines = (old or b"").splitlines()
    missing = [
        ignore
        for ignore in IGNORES
        if not any(v.encode() in lines for v in (ignore, ignore.rstrip("/"), "/" + ignore))
    ]
    if not missing:
        said.append(f"kept      {gitignore} (it ignores {' and '.join(IGNORES)})")
    else:
        new = old
        for ignore in missing:
            new = _with_line(gitignore, new, ignore)
        batch.add(_target(gitignore, project), new, old)
        said.append(f"{'created' if old is None else 'extended':<9} {gitignore}")
    batch.commit()
    return said


def _read(path: Path) -> bytes | None:
    """The bytes of the file `path`, None when there is none (or only a link to nothing); a
    folder, FIFO or device there is refused, never opened (a FIFO would wait for a writer)."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise InitRefused(str(path), "is not a regular file; init changes nothing in it")
        return path.read_bytes()
    except FileNotFoundError:
        return None


def _target(path: Path, project: Path) -> Path:
    """The real path `path` is written at, links followed; refused when that is outside the
    project folder (a link, of the file or of a folder on its way, leads out of it)."""
    real = path.resolve()
    if real != project and project not in real.parents:
        raise InitRefused(
            str(path),
            f"leads to {real} (a symbolic link), outside the project folder {project}; init "
            "writes nothing outside it (replace the link with a file, or add the lines by hand)",
        )
    return real


def _toml_text(pyproject: Path, data: bytes) -> str:
    """The text of a pyproject.toml as TOML readers see it (UTF-8, no newline translation); a
    ConfigError for an encoding they refuse, which init does not edit either."""
    from collide2d.runner.command.settings import ConfigError

    def refuse(why: str, line: int = 1, col: int = 1):
        return ConfigError(str(pyproject), line, col, f"{why}; init changes nothing in it")

    if data.startswith(codecs.BOM_UTF8):
        raise refuse(
            "the file begins with a byte order mark (BOM), which TOML readers (tomllib, pip) "
            "refuse: save it as UTF-8 without a BOM"
        )
    if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) or b"\0" in data:
        raise refuse("the file is UTF-16 (or holds NUL bytes); TOML files are UTF-8")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        why = f"not UTF-8 (byte 0x{data[exc.start]:02x}); TOML files are UTF-8"
        raise refuse(why, line, col) from None


def _with_table(pyproject: Path, text: str, data: dict) -> str:
    """`text` with TABLE_TEXT appended, in the file's line ends; a ConfigError when that would
    not say what `text` said plus the table (a `tool` that is an inline table, an array of tables
    or a value: TOML lets no `[tool.collide2d]` section extend those)."""
    from collide2d.runner.command.settings import ConfigError, parse

    newline = "\r\n" if text.split("\n", 1)[0].endswith("\r") else "\n"
    sep = "" if not text or text.endswith("\n") else newline
    if text and not (text + sep).endswith(newline * 2):
        sep += newline
    new = text + sep + TABLE_TEXT.replace("\n", newline)
    expected = dict(data)
    table = parse(TABLE_TEXT, "")["tool"]["collide2d"]
    tool = data.get("tool")
    if isinstance(tool, dict):
        expected["tool"] = {**tool, "collide2d": table}
    elif "tool" not in data:
        expected["tool"] = {"collide2d": table}
    try:
        same = repr(parse(new, pyproject)) == repr(expected) and "tool" in expected
    except ConfigError:
        same = False
    if same:
        return new
    inline = re.search(r"^[ \t]*tool[ \t]*=", text, re.MULTILINE)
    array = re.search(r"^[ \t]*\[\[[ \t]*tool[ \t]*\]\]", text, re.MULTILINE)
    if isinstance(tool, dict) and inline:
        why = "`tool` is an inline table (tool = {...}), which no [tool.collide2d] section extends"
    elif isinstance(tool, list):
        why = "`tool` is an array of tables ([[tool]]), not a table"
    elif "tool" in data and not isinstance(tool, dict):
        why = f"`tool` is a value ({type(tool).__name__}), not a table"
    else:
        why = "a [tool.collide2d] table added at its end would change what the file says"
    at = inline or array
    line = text.count("\n", 0, at.start()) + 1 if at else 1
    raise ConfigError(
        str(pyproject),
        line,
        1,
        f"{why}; init changes nothing in it: add collide2d's settings by hand "
        "(`collide2d config` then shows what it reads)",
    )


def _with_line(path: Path, old: bytes | None, line: str) -> bytes:
    """The bytes of the text file `path` (`old`, None when new) with `line` added on a line of
    its own, in the file's line ends; refused for a UTF-16 file, which bytes cannot extend."""
    if not old:
        return line.encode("ascii") + b"\n"
    if old.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)) or b"\0" in old:
        raise InitRefused(
            str(path), "the file is UTF-16 (or holds NUL bytes); init changes nothing in it"
        )
    newline = b"\r\n" if old.split(b"\n", 1)[0].endswith(b"\r") else b"\n"
    sep = b"" if old.endswith(b"\n") else newline
    return old + sep + line.encode("ascii") + newline
