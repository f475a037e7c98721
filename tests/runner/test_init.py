"""Tests of `collide2d init` (runner/command/newproject.py) and of a project made by it: plain
`pytest` collects one golden test per scenario through the plugin, with no test file or conftest,
and `check` and `bless` read the same [tool.collide2d] table."""

from __future__ import annotations

import codecs
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from collide2d.runner.command import newproject, settings
from collide2d.runner.command.main import main
from collide2d.runner.golden.store import GoldenStore
from collide2d.runner.scenario.load import load

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

if os.name == "posix":
    import resource
    import signal

pytest_plugins = ["pytester"]

# the nested in-process runs leave out the cache and pytest-playwright, whose per-test hook keeps
# global state that a run inside a run trips on
NESTED = ("-p", "no:cacheprovider", "-p", "no:playwright")


def test_init_makes_a_project_and_prints_the_next_three_commands(tmp_path, capsys):
    assert main(["init", str(tmp_path / "p")]) == 0
    out = capsys.readouterr().out
    root = tmp_path / "p"
    example = root / "scenarios" / "example.yaml"
    scenario = load(example)
    assert scenario.name == "example"
    # a model that collides each shape as itself: the example's ball collides as a circle
    assert (scenario.model, scenario.geometry) == ("stepped", "exact")
    assert any(o.get("shape") == "circle" for o in yaml.safe_load(example.read_text())["objects"])
    text = example.read_text()
    for section in ("version", "name", "description", "world", "model", "ticks", "objects",
                    "generate", "output", "golden"):  # fmt: skip
        assert f"\n{section}:" in "\n" + text, section
    assert text.count("#") >= 10  # commented
    assert settings.find(root).file == (root / "pyproject.toml").resolve()
    assert (root / ".gitignore").read_text() == "out/\nreport/\n"  # run's and check's folders
    commands = [line.split("#")[0].strip() for line in out.splitlines()[-3:]]
    assert commands == ["collide2d run scenarios/example.yaml", "pytest --update-goldens", "pytest"]


def test_init_adds_to_a_gitignore_only_the_folders_it_does_not_ignore(tmp_path, capsys):
    (tmp_path / ".gitignore").write_text("out\n")
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / ".gitignore").read_text() == "out\nreport/\n"
    (tmp_path / ".gitignore").write_text("/report/\nout/\n")
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / ".gitignore").read_text() == "/report/\nout/\n"
    assert "(it ignores out/ and report/)" in capsys.readouterr().out


def test_init_extends_what_is_there_and_overwrites_nothing(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "mine"\n')
    (tmp_path / ".gitignore").write_text("*.pyc")
    (tmp_path / "scenarios").mkdir()
    (tmp_path / "scenarios" / "example.yaml").write_text("version: 1\n")
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / "scenarios" / "example.yaml").read_text() == "version: 1\n"
    assert (tmp_path / "pyproject.toml").read_text().startswith('[project]\nname = "mine"\n\n')
    assert settings.has_table(tmp_path / "pyproject.toml")
    assert (tmp_path / ".gitignore").read_text() == "*.pyc\nout/\nreport/\n"
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert main(["init", str(tmp_path)]) == 0  # again: everything kept
    assert {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()} == before
    out = capsys.readouterr().out
    assert out.count("kept") >= 3


def test_init_refuses_a_pyproject_that_is_not_toml_before_writing_anything(tmp_path, capsys):
    (tmp_path / "pyproject.toml").write_text("[project\n")
    assert main(["init", str(tmp_path)]) == 2
    assert "pyproject.toml:1:" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pyproject.toml"]


@pytest.fixture
def inited(pytester, monkeypatch):
    """A pytester project made by `collide2d init`, with a second scenario (run as on a
    developer's machine: --update-goldens is refused where CI is set)."""
    monkeypatch.delenv("CI", raising=False)
    assert main(["init", str(pytester.path)]) == 0
    text = (pytester.path / "scenarios" / "example.yaml").read_text()
    (pytester.path / "scenarios" / "second.yaml").write_text(
        text.replace("name: example", "name: second")
    )
    return pytester


def test_plain_pytest_collects_one_golden_test_per_scenario_and_update_goldens_blesses(inited):
    assert not list(inited.path.rglob("*.py"))
    result = inited.runpytest("-v", *NESTED)
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*scenarios/example.yaml::golden FAILED*"])
    result.stdout.fnmatch_lines(["*to create it: collide2d bless scenarios/example.yaml*"])
    inited.runpytest("--update-goldens", *NESTED).assert_outcomes(passed=2)
    assert GoldenStore(inited.path).names() == ["example", "second"]
    result = inited.runpytest("-v", *NESTED)
    result.assert_outcomes(passed=2)
    result.stdout.fnmatch_lines(["*scenarios/second.yaml::golden PASSED*"])


def test_a_project_without_the_table_is_untouched(pytester):
    (pytester.path / "scenarios").mkdir()
    (pytester.path / "scenarios" / "a.yaml").write_text("version: 1\nticks: 1\n")
    result = pytester.runpytest(*NESTED)
    assert result.ret == pytest.ExitCode.NO_TESTS_COLLECTED


def test_check_and_bless_use_the_tables_folders(tmp_path, monkeypatch, capsys):
    assert main(["init", str(tmp_path)]) == 0
    pyproject = tmp_path / "pyproject.toml"
    text = (
        pyproject.read_text().replace('"scenarios"', '"cases"').replace('"goldens"', '"expected"')
    )
    pyproject.write_text(text)
    (tmp_path / "scenarios").rename(tmp_path / "cases")
    sub = tmp_path / "deep"
    sub.mkdir()
    monkeypatch.chdir(sub)  # found upward
    monkeypatch.delenv("CI", raising=False)
    assert main(["check"]) == 1  # no golden yet
    assert main(["bless"]) == 0
    assert GoldenStore(tmp_path, "expected").names() == ["example"]
    assert not (tmp_path / "goldens").exists()
    capsys.readouterr()
    assert main(["check", "example", "--report"]) == 0
    out = capsys.readouterr().out
    assert "1 passed, 0 failed" in out
    assert (tmp_path / "report" / "index.html").is_file()  # the table's report folder


def test_the_plugin_reads_a_custom_scenarios_folder(pytester, monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    assert main(["init", str(pytester.path)]) == 0
    pyproject = pytester.path / "pyproject.toml"
    pyproject.write_text(
        pyproject.read_text().replace('scenarios = "scenarios"', 'scenarios = "cases"')
    )
    (pytester.path / "scenarios").rename(pytester.path / "cases")
    result = pytester.runpytest("--update-goldens", "-v", *NESTED)
    result.assert_outcomes(passed=1)
    result.stdout.fnmatch_lines(["*cases/example.yaml::golden PASSED*"])
    assert Path(pytester.path / "goldens" / "example" / "manifest.json").is_file()


def _toml(path: Path) -> dict:
    """The file as a TOML reader (pip, setuptools) reads it: bytes, UTF-8, no newline changes."""
    return tomllib.loads(path.read_bytes().decode("utf-8"))


TABLE = tomllib.loads(newproject.TABLE_TEXT)["tool"]["collide2d"]


@pytest.mark.parametrize(
    "text",
    [
        '[project]\nname = "mine"\n',
        '[tool]\nblack.line-length = 88\nruff.lint.select = ["E"]\n',  # dotted keys under [tool]
        'tool.black.line-length = 88\n[project]\nname = "x"\n',  # dotted keys at the top
        "tool.black = {line-length = 88}\n",  # an inline table inside a dotted `tool`
        '[project]\r\nname = "crlf"\r\n[tool.black]\r\nline-length = 88\r\n',  # CRLF line ends
        "[tool.ruff]\nline-length = 99 # no newline at the end",
        "x = nan\nwhen = 1979-05-27T07:32:00Z\n# a comment last\n\n\n",
        "",
    ],
    ids=["plain", "tool-dotted", "root-dotted", "inline-inside", "crlf", "no-eol", "odd", "empty"],
)
def test_init_adds_its_table_keeping_what_the_pyproject_says(tmp_path, capsys, text):
    pyproject = tmp_path / "pyproject.toml"
    pyproject.write_bytes(text.encode())
    before = tomllib.loads(text)
    assert main(["init", str(tmp_path)]) == 0
    after = _toml(pyproject)
    assert after["tool"].pop("collide2d") == TABLE
    if not after["tool"] and "tool" not in before:
        del after["tool"]
    assert repr(after) == repr(before)  # repr: nan == nan
    data = pyproject.read_bytes()
    assert data.startswith(text.encode())  # appended, nothing else touched
    if "\r\n" in text:  # the file's line ends kept: no bare LF
        assert data.count(b"\n") == data.count(b"\r\n")
    else:
        assert b"\r" not in data
    assert settings.find(tmp_path).file == pyproject.resolve()


@pytest.mark.parametrize(
    ("data", "where", "says"),
    [
        (b"tool = {black = {line-length = 88}}\n", ":1:1:", "inline table"),
        (b'# mine\n\ntool = {}\n[project]\nname = "x"\n', ":3:1:", "inline table"),
        (b"[[tool]]\nname = 1\n", ":1:1:", "array of tables"),
        (b"tool = 1\n", ":1:1:", "not a table"),
        (codecs.BOM_UTF8 + b'[project]\nname = "x"\n', ":1:1:", "byte order mark"),
        ('[project]\nname = "x"\n'.encode("utf-16"), ":1:1:", "UTF-16"),
        ('[project]\nname = "x"\n'.encode("utf-16-le"), ":1:1:", "UTF-16"),
        (b'[project]\nname = "\xe9"\n', ":2:9:", "not UTF-8"),
        (b'[project]\rname = "cr-only"\r', ":1:", "not valid TOML"),
    ],
    ids=["inline", "inline-late", "array", "value", "bom", "utf16", "utf16-nobom", "latin1", "cr"],
)
def test_init_refuses_a_pyproject_it_cannot_extend_and_writes_nothing(
    tmp_path, capsys, data, where, says
):
    (tmp_path / "pyproject.toml").write_bytes(data)
    assert main(["init", str(tmp_path)]) == 2
    (err,) = capsys.readouterr().err.splitlines()
    assert err.startswith(f"{tmp_path / 'pyproject.toml'}{where}") and " error: " in err, err
    assert says in err
    assert (tmp_path / "pyproject.toml").read_bytes() == data
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pyproject.toml"]


@pytest.mark.parametrize("link", ["pyproject.toml", ".gitignore", "scenarios"])
@pytest.mark.parametrize("dangling", [False, True], ids=["to-a-file", "to-nothing"])
def test_init_writes_nothing_through_a_link_that_leads_outside(tmp_path, capsys, link, dangling):
    project, outside = tmp_path / "p", tmp_path / "elsewhere"
    project.mkdir()
    outside.mkdir()
    target = outside / ("dir" if link == "scenarios" else "file")
    if not dangling:
        if link == "scenarios":
            target.mkdir()
        else:
            target.write_text("# kept\n")
    (project / link).symlink_to(target)
    assert main(["init", str(project)]) == 2
    err = capsys.readouterr().err
    assert "outside the project folder" in err and "(a symbolic link)" in err
    assert sorted(p.name for p in project.iterdir()) == [link]  # nothing else written
    if dangling:
        assert not target.exists()
    elif link == "scenarios":
        assert not list(target.iterdir())
    else:
        assert target.read_text() == "# kept\n"


def test_init_writes_through_a_link_inside_the_project_keeping_the_link(tmp_path):
    (tmp_path / "conf").mkdir()
    (tmp_path / "conf" / "pyproject.toml").write_text('[project]\nname = "x"\n')
    (tmp_path / "pyproject.toml").symlink_to(Path("conf") / "pyproject.toml")
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / "pyproject.toml").is_symlink()
    assert _toml(tmp_path / "conf" / "pyproject.toml")["tool"]["collide2d"] == TABLE


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs a process size limit (POSIX)")
@pytest.mark.parametrize("fails", ["pyproject.toml", ".gitignore"])
def test_init_is_all_or_nothing_when_a_file_cannot_be_written(tmp_path, fails):
    """A file-size limit (RLIMIT_FSIZE, root or not) fails the write of the one large file: the
    other files init would create or extend stay as they were, none is left half written."""
    big = "#" * 6000 + "\n"  # the example (2.4 kB) and the other file stay under the limit
    extra = {fails: big}
    (tmp_path / "pyproject.toml").write_text(
        '[project]\nname = "x"\n' + extra.get("pyproject.toml", "")
    )
    (tmp_path / ".gitignore").write_text("*.pyc\n" + extra.get(".gitignore", ""))
    before = {p: p.read_bytes() for p in tmp_path.iterdir()}

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past it fails with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (5000, 5000))

    result = subprocess.run(
        [sys.executable, "-m", "collide2d", "init", str(tmp_path)],
        preexec_fn=limit,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"collide2d: error: {tmp_path / fails}: File too large")
    assert {p: p.read_bytes() for p in tmp_path.iterdir()} == before  # no temporaries either


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("name", ["pyproject.toml", ".gitignore"])
def test_init_refuses_a_fifo_in_place_of_a_file_at_once(tmp_path, name):
    os.mkfifo(tmp_path / name)  # opened, it would wait for a writer forever
    result = subprocess.run(
        [sys.executable, "-m", "collide2d", "init", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert (
        result.stderr
        == f"{tmp_path / name}: error: is not a regular file; init changes nothing in it\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]


def test_init_extends_a_gitignore_in_its_own_bytes_and_line_ends(tmp_path, capsys):
    """A .gitignore is bytes to git: one in Latin-1 with CRLF line ends gets `out/` in CRLF, its
    bytes kept; one in UTF-16, which bytes cannot extend, is refused before anything is written."""
    old = b"# caf\xe9\r\n*.pyc"
    (tmp_path / ".gitignore").write_bytes(old)
    assert main(["init", str(tmp_path)]) == 0
    assert (tmp_path / ".gitignore").read_bytes() == old + b"\r\nout/\r\nreport/\r\n"
    utf16 = tmp_path / "u"
    utf16.mkdir()
    (utf16 / ".gitignore").write_bytes("*.pyc\n".encode("utf-16"))
    assert main(["init", str(utf16)]) == 2
    assert "UTF-16" in capsys.readouterr().err
    assert sorted(p.name for p in utf16.iterdir()) == [".gitignore"]
