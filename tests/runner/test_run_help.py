"""`collide2d run --help` leads with examples, each one a command line the parser takes, and
keeps the --max-* limits in a group of their own, after the options a user reaches for."""

from __future__ import annotations

import re

import pytest

from collide2d.runner.command.main import build_parser, main


def run_help(capsys) -> str:
    with pytest.raises(SystemExit) as info:
        main(["run", "--help"])
    assert info.value.code == 0
    return capsys.readouterr().out


def test_run_help_leads_with_examples_the_parser_takes(capsys):
    text = run_help(capsys)
    usage, rest = text.split("\n", 1)
    assert len(usage) <= 80  # one short line, not every option
    assert rest.index("examples:") < rest.index("options:")
    examples = re.findall(r"^  (collide2d run\b.*?)(?:\s{2,}.*)?$", rest, flags=re.M)
    assert len(examples) >= 4
    for line in examples:
        args = build_parser("run").parse_args(line.split()[1:])
        assert args.command == "run", line


def test_run_help_groups_the_limits_apart(capsys):
    text = run_help(capsys)
    headings = re.findall(r"^(\S[^\n]*):$", text, flags=re.M)
    assert headings[-1] == "limits"  # the last group
    limits = text[text.index("\nlimits:\n") :]
    before = text[: text.index("\nlimits:\n")]
    options = set(re.findall(r"^  (--max-[a-z-]+)", text, flags=re.M))
    assert {"--max-objects", "--max-ticks", "--max-events-per-tick"} <= options
    for option in options:
        assert re.search(rf"^  {option}\b", limits, flags=re.M), option
        assert not re.search(rf"^  {option}\b", before, flags=re.M), option
    # the options a user reaches for come in groups of their own before them
    for heading in ("what is written", "instead of the scenario's settings", "how it runs"):
        assert any(h.startswith(heading) for h in headings[:-1]), heading
