"""The code blocks of the README and the docs pages, and a runner for their console sessions.

`blocks(path)` reads a Markdown file's fenced blocks as (language, text, line). A `console` block
is a session: `$ COMMAND` lines, each followed by the output it shows. `run_session` runs each
command with bash in a folder (a `cd` carries over to the next command, as in a terminal) and
compares what it printed (stdout and stderr together) with what the page shows: a line `...`
stands for any lines, `...` inside a line for any text. A command that shows no output must
succeed. `collide2d_lines` gives every `collide2d ...` command line of the other shell blocks, for
the argument parser to check.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([\w+-]*)")


@dataclass
class Block:
    lang: str
    text: str
    line: int  # where the block starts, for messages
    path: Path

    def where(self) -> str:
        return f"{self.path.relative_to(ROOT)}:{self.line}"


def doc_files() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def blocks(path: Path) -> list[Block]:
    found, lines = [], path.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, lang = m.group(1), m.group(2), m.group(3)
        body, start, i = [], i + 1, i + 1
        while i < len(lines) and not lines[i].strip().startswith(fence):
            body.append(lines[i][len(indent) :] if lines[i].startswith(indent) else lines[i])
            i += 1
        found.append(Block(lang, "\n".join(body) + "\n", start, path))
        i += 1
    return found


def all_blocks(*langs: str) -> list[Block]:
    return [b for p in doc_files() for b in blocks(p) if b.lang in langs]


# ---------------------------------------------------------------------------------------------
# console sessions


@dataclass
class Step:
    command: str
    shown: list[str]


def steps(block: Block) -> list[Step]:
    out: list[Step] = []
    for line in block.text.splitlines():
        if line.startswith("$ "):
            out.append(Step(line[2:], []))
        elif out:
            out[-1].shown.append(line)
        elif line.strip():
            raise AssertionError(f"{block.where()}: output before any command: {line!r}")
    return out


def _line_matches(pattern: str, line: str) -> bool:
    if "..." not in pattern:
        return pattern.rstrip() == line.rstrip()
    parts = [re.escape(p) for p in pattern.rstrip().split("...")]
    return re.fullmatch(".*?".join(parts), line.rstrip(), flags=re.DOTALL) is not None


def matches(shown: list[str], printed: list[str]) -> bool:
    """`printed` as `shown` says it: `...` alone on a line is any lines (none too)."""
    if not shown:
        return not printed
    head, rest = shown[0], shown[1:]
    if head.strip() == "...":
        return any(matches(rest, printed[k:]) for k in range(len(printed) + 1))
    return bool(printed) and _line_matches(head, printed[0]) and matches(rest, printed[1:])


def session_env() -> dict:
    """A user's shell: this interpreter's scripts first on PATH, no CI, no pytest of ours."""
    drop = ("CI", "PYTHONPATH", "COLUMNS", "PYTEST_ADDOPTS", "PYTEST_CURRENT_TEST")
    env = {
        k: v for k, v in os.environ.items() if k not in drop and not k.startswith("PYTEST_XDIST")
    }
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    env["NO_COLOR"] = "1"
    return env


def run_session(block_list: list[Block], folder: Path) -> None:
    """Run the sessions of `block_list` one after another, starting in `folder`."""
    env, cwd = session_env(), folder
    pwd_file = folder.parent / f".{folder.name}.pwd"
    for block in block_list:
        for step in steps(block):
            script = f"{step.command}\nstatus=$?\npwd > {shlex.quote(str(pwd_file))}\nexit $status"
            proc = subprocess.run(
                ["bash", "-c", script],
                cwd=cwd,
                env=env,
                capture_output=True,
                text=True,
                timeout=600,
            )
            cwd = Path(pwd_file.read_text().strip())
            printed = (proc.stdout + proc.stderr).splitlines()
            while printed and not printed[-1].strip():
                printed.pop()
            shown = list(step.shown)
            while shown and not shown[-1].strip():
                shown.pop()
            context = f"{block.where()}: $ {step.command} (exit {proc.returncode})"
            if not shown:
                assert proc.returncode == 0, f"{context}\n{proc.stdout}{proc.stderr}"
            assert matches(shown, printed), (
                f"{context}\n--- the page shows:\n" + "\n".join(shown)
                + "\n--- it printed:\n" + "\n".join(printed)
            )


# ---------------------------------------------------------------------------------------------
# collide2d command lines of the other shell blocks


def collide2d_lines(block: Block) -> list[str]:
    """Each `collide2d ...` command of a shell block, joined over `\\` line ends, comments off."""
    text = re.sub(r"\\\n\s*", " ", block.text)
    found = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("$ "):
            line = line[2:]
        for part in re.split(r"&&|;|\||>", line):
            words = shlex.split(part, comments=True)
            # env assignments, and a YAML list item's `- run:` / `- ` before a job's command
            while words and re.fullmatch(r"[A-Z_]+=\S*|-|[a-z_]+:", words[0]):
                words = words[1:]
            if words[:1] == ["collide2d"]:
                found.append(shlex.join(words[1:]))
            elif words[:3] == ["python", "-m", "collide2d"]:
                found.append(shlex.join(words[3:]))
    return found
