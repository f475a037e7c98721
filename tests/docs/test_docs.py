"""The README and the docs site cannot rot: the README stays a front door of at most 150 lines,
the site builds with `mkdocs build --strict` (a broken link or anchor, or a page missing from the
navigation, fails it), the generated reference pages name every command, option and scenario key,
every console session of a page runs and prints what the page shows, every other `collide2d`
command line shown is one the parser takes, and every scenario shown loads."""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import io
import re
import shutil
import subprocess
import sys

import pytest
import yaml
from docblocks import (
    ROOT,
    all_blocks,
    blocks,
    collide2d_lines,
    doc_files,
    run_session,
    session_env,
)
from PIL import Image, ImageSequence

README = ROOT / "README.md"
SHELLS = ("sh", "bash", "shell", "console")


def test_the_readme_is_a_front_door_of_at_most_150_lines():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    for heading in ("## Quick start", "## Use collide2d in your project", "## Commands"):
        assert heading in text
    assert "pip install -e . && collide2d run" in text  # the quick start's two commands
    assert 'pip install -e ".[test]" && pytest' in text


def test_every_relative_link_of_the_readme_leads_to_a_file():
    text = README.read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text)
    local = [link for link in links if "://" not in link]
    assert local, "the README links into the docs"
    missing = [link for link in local if not (ROOT / link).exists()]
    assert not missing


def test_the_readmes_demo_gif_is_what_the_demo_draws(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "collide2d", "run", "--out", str(tmp_path), "--quiet"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        env=session_env(),
    )
    assert proc.returncode == 0, proc.stderr
    made = tmp_path / "paper_fifty_boxes" / "animation.gif"

    def frames(image):
        return [
            (f.convert("RGB").tobytes(), f.info.get("duration"))
            for f in ImageSequence.Iterator(image)
        ]

    with Image.open(ROOT / "docs" / "demo.gif") as shown, Image.open(made) as drawn:
        a, b = frames(shown), frames(drawn)
    assert len(a) == len(b) > 1 and a == b, "remake docs/demo.gif: collide2d run, then copy it"


def gif_frames(path):
    """Each frame of a GIF as (RGB bytes, duration)."""
    with Image.open(path) as image:
        return [
            (f.convert("RGB").tobytes(), f.info.get("duration"))
            for f in ImageSequence.Iterator(image)
        ]


@pytest.mark.parametrize(
    "name", ["bouncing_ball", "stack", "sliding_block", "projectile", "pile", "cradle"]
)
def test_the_readmes_gravity_gifs_are_what_their_scenarios_draw(tmp_path, name):
    from collide2d.runner.command.main import main

    scenario = ROOT / "scenarios" / f"gravity_{name}.yaml"
    assert main(["run", str(scenario), "--out", str(tmp_path), "--quiet"]) == 0
    shown = gif_frames(ROOT / "docs" / "gravity" / f"{name}.gif")
    drawn = gif_frames(tmp_path / f"gravity_{name}" / "animation.gif")
    assert len(shown) == len(drawn) > 1 and shown == drawn, (
        f"remake docs/gravity/{name}.gif: collide2d run {scenario.relative_to(ROOT)}, then copy "
        "its animation.gif"
    )
    assert f"](docs/gravity/{name}.gif)" in (ROOT / "README.md").read_text()


def _parse(line: str) -> str | None:
    """None when the parser takes the command line, else its complaint."""
    from collide2d.runner.command.main import build_parser

    argv = line.split() if not line else __import__("shlex").split(line)
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            args = build_parser().parse_args(argv)
    except SystemExit as stop:
        if stop.code == 0:  # --help, --version
            return None
        return err.getvalue().strip().splitlines()[-1]
    return None if isinstance(args, argparse.Namespace) else "no namespace"


# The plugin how-to's commands name the example plugin, which is installed only where CI's plugin
# step installs it (a fresh virtualenv, where they run): the tests below leave that page out.
PLUGIN_PAGE = ROOT / "docs" / "how-to" / "plugins.md"


def shown(*langs: str) -> list:
    """The blocks of `langs` of every page but the plugin how-to."""
    return [b for b in all_blocks(*langs) if b.path != PLUGIN_PAGE]


def test_every_collide2d_command_line_shown_is_one_the_parser_takes():
    lines = [(b, line) for b in shown(*SHELLS) for line in collide2d_lines(b)]
    assert len(lines) > 30
    refused = [
        f"{b.where()}: collide2d {line}: {why}" for b, line in lines if (why := _parse(line))
    ]
    assert not refused, "\n".join(refused)


# The commands a test runs, beside parsing them: the quick ones, in a copy of the project's
# scenarios and goldens (bench, stress, sweep and a check of the whole corpus take minutes, and
# their sessions are the business of their own tests; `bless` writes goldens).
RUN_VERBS = ("run", "validate", "schema", "config", "init", "--version")


@pytest.mark.slow  # a minute: a run of every quick command the pages show
def test_every_quick_collide2d_command_shown_runs(tmp_path, monkeypatch):
    import shlex

    monkeypatch.delenv("CI", raising=False)
    project = tmp_path / "project"
    for folder in ("scenarios", "goldens", "sweeps"):
        shutil.copytree(ROOT / folder, project / folder)
    lines = {line for b in shown(*SHELLS) for line in collide2d_lines(b)}
    quick = sorted(
        line for line in lines
        if shlex.split(line)[:1] and shlex.split(line)[0] in RUN_VERBS
        or (line.startswith("check scenarios/") and "--scheduler" not in line)
    )
    assert len(quick) >= 15
    failed = []
    for line in quick:
        proc = subprocess.run(
            [sys.executable, "-m", "collide2d", *shlex.split(line)],
            cwd=project,
            capture_output=True,
            text=True,
            env=session_env(),
            timeout=600,
        )
        if proc.returncode != 0:
            failed.append(f"collide2d {line}: exit {proc.returncode}: {proc.stderr.strip()}")
    assert not failed, "\n".join(failed)


def test_every_scenario_shown_loads_and_runs(tmp_path):
    from collide2d.runner.scenario.load import load

    shown = []
    for path in doc_files():
        page = blocks(path)
        tables = {b.text.split("\n", 1)[0]: b for b in page if b.lang == "csv"}
        for block in page:
            if block.lang != "yaml" or not re.search(r"^version: 1$", block.text, re.M):
                continue
            folder = tmp_path / f"s{len(shown)}"
            folder.mkdir()
            for header, table in tables.items():
                (folder / "bodies.csv").write_text(table.text, encoding="utf-8")
                assert header.startswith("id,")
            scenario = folder / "scenario.yaml"
            scenario.write_text(block.text, encoding="utf-8")
            try:
                load(str(scenario))
            except Exception as err:  # noqa: BLE001 - the message names the block
                pytest.fail(f"{block.where()}: {err}")
            proc = subprocess.run(
                [sys.executable, "-m", "collide2d", "run", scenario, "--out", "out", "--quiet"],
                cwd=folder,
                capture_output=True,
                text=True,
                env=session_env(),
            )
            assert proc.returncode == 0, f"{block.where()}: {proc.stderr}"
            assert list((folder / "out").glob("*/summary.json")), block.where()
            shown.append(block)
    assert len(shown) >= 3


def test_every_sweep_file_shown_reads_as_a_sweep(tmp_path):
    from collide2d.runner.sweep import sweepfile

    shown = [b for b in all_blocks("yaml") if re.search(r"^sweep: 1$", b.text, re.M)]
    assert shown
    for k, block in enumerate(shown):
        folder = tmp_path / f"p{k}"
        (folder / "sweeps").mkdir(parents=True)
        (folder / "scenarios").mkdir()
        for scenario in (ROOT / "scenarios").glob("*.yaml"):
            (folder / "scenarios" / scenario.name).write_bytes(scenario.read_bytes())
        path = folder / "sweeps" / "shown.yaml"
        path.write_text(block.text, encoding="utf-8")
        assert sweepfile.is_sweep_file(str(path)), block.where()
        paths, axes, seeds = sweepfile.read(str(path))
        assert paths and axes and seeds, block.where()


def test_the_python_shown_runs_and_makes_the_table_it_says(tmp_path, monkeypatch):
    from collide2d.runner.scenario.load import load

    (block,) = [b for b in blocks(ROOT / "docs" / "how-to" / "tables.md") if b.lang == "python"]
    monkeypatch.chdir(tmp_path)
    exec(compile(block.text, block.where(), "exec"), {})
    (tmp_path / "crowd.yaml").write_text(
        "version: 1\nworld: {width: 800, height: 800, fps: 30}\nmodel: stepped\nticks: 1\n"
        "objects: {file: bodies.npy}\n",
        encoding="utf-8",
    )
    assert len(load(str(tmp_path / "crowd.yaml")).names) == 10_000
    # the API page's and the plugin how-to's Python run in tests/api and CI's plugin step
    others = [b for b in shown("python") if b.path.name not in ("tables.md", "api.md")]
    assert not others


def test_every_wheel_the_docs_name_is_of_this_version():
    version = re.search(r'^version = "([^"]+)"', (ROOT / "pyproject.toml").read_text(), re.M)[1]
    named = [
        (path, found)
        for path in doc_files()
        for found in re.findall(r"collide2d-([0-9][^-]*)-py3-none-any\.whl", path.read_text())
    ]
    assert named and all(found == version for _path, found in named), named


def test_every_yaml_block_is_yaml_and_the_ci_jobs_run_check_with_junit_and_report():
    for block in all_blocks("yaml", "toml"):
        if block.lang == "yaml":
            yaml.safe_load(block.text)
    ci = blocks(ROOT / "docs" / "how-to" / "ci.md")
    jobs = [b for b in ci if b.lang == "yaml"]
    assert len(jobs) >= 2
    for job in jobs:
        checks = [line for line in collide2d_lines(job) if line.startswith("check")]
        assert any("--junit" in c and "--report" in c for c in checks), job.where()
        assert _parse(checks[0]) is None
        assert "NUMBA_CACHE_DIR" in job.text


SESSION_PAGES = sorted({b.path for b in shown("console")})


@pytest.mark.slow  # a minute: the tutorial runs pytest four times
# (not `page`: pytest-playwright's fixture of that name would run it once per browser)
@pytest.mark.parametrize("doc_page", SESSION_PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_console_session_prints_what_its_page_shows(doc_page, tmp_path, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    folder = tmp_path / "work"
    folder.mkdir()
    if doc_page.parent.name != "tutorial":  # the other pages' sessions use the project's scenes
        shutil.copytree(ROOT / "scenarios", folder / "scenarios")
    run_session([b for b in blocks(doc_page) if b.lang == "console"], folder)


def test_the_tutorial_has_sessions_that_fail_and_pass_as_ci_does():
    sessions = [b for b in blocks(ROOT / "docs" / "tutorial" / "index.md") if b.lang == "console"]
    text = "".join(b.text for b in sessions)
    assert "$ CI=true pytest" in text and "1 failed" in text and "1 passed" in text


# ---------------------------------------------------------------------------------------------
# the site


def test_the_generated_pages_name_every_command_option_and_scenario_key():
    sys.path.insert(0, str(ROOT))
    try:
        from docgen import reference
    finally:
        sys.path.remove(str(ROOT))
    parser, commands, _ = reference.command_parsers()
    page = reference.commands_page()
    for name, sub in commands.items():
        assert f"## {name}\n" in page
        for action in sub._actions:
            for flag in action.option_strings:
                if flag not in ("-h", "--help"):
                    assert f"`{flag}" in page, (name, flag)
    from collide2d.runner.scenario.schema import json_schema

    schema, text = json_schema(), reference.schema_page()

    def keys(node):
        if isinstance(node, dict):
            for key, sub in node.get("properties", {}).items():
                yield key
                yield from keys(sub)
            for sub in node.values():
                if isinstance(sub, (dict, list)):
                    yield from keys(sub)
        elif isinstance(node, list):
            for sub in node:
                yield from keys(sub)

    for key in set(keys(schema)):
        assert f"`{key}`" in text, key  # a row of its own, or named in its mapping
    from collide2d.runner.command import settings

    settings_text = reference.settings_page()
    keys = (*settings.FOLDER_KEYS, "threads", "jit", *settings.LIMIT_KEYS, *settings.MODEL_KEYS)
    for key in keys:
        assert f"| `{key}` |" in settings_text, key


@pytest.mark.slow  # half a minute or more: the build runs the scenarios its pictures show
@pytest.mark.skipif(
    importlib.util.find_spec("mkdocs") is None
    or importlib.util.find_spec("material") is None
    or importlib.util.find_spec("mkdocstrings") is None,
    reason="the docs extra is not installed (pip install -e '.[docs]'); CI installs it",
)
def test_the_site_builds_strictly(tmp_path):
    site = tmp_path / "site"
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=session_env(),
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    for page in ("reference/commands", "reference/schema", "reference/settings", "changelog"):
        assert (site / page / "index.html").is_file(), page
    for picture in ("explanation/fig2.png", "explanation/tunnelling.png", "tutorial/diff.png"):
        assert (site / picture).stat().st_size > 500
    commands = (site / "reference" / "commands" / "index.html").read_text(encoding="utf-8")
    assert "--from-report" in commands and "--max-events-per-tick" in commands
    api = (site / "reference" / "api" / "index.html").read_text(encoding="utf-8")
    assert "collide2d" in api and "doc-module" in api  # mkdocstrings rendered the package
