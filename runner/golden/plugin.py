"""The pytest plugin of the goldens: every scenario a test, `test_golden[fig2_case1]`
(docs/goldens.md#pytest).

Registered through the `pytest11` entry point of the distribution, so it loads in the pytest run of
any project that installs collide2d. Inputs: the scenario files of the project (`ROOT/scenarios/`,
ROOT found upward from the current directory or given by `--golden-root`; the folders and the
scenarios' limits and model defaults come from ROOT's `[tool.collide2d]` table,
runner.command.settings) and the options below. In a project with that table, every scenario file of
its scenarios folder is collected as one test, `scenarios/NAME.yaml::golden`, with no test file or
conftest; other projects are untouched. Outputs: test outcomes whose failure text is the same as
`collide2d check` prints, a report per failing scenario, and with `--update-goldens` the goldens of
the tests that ran.

    --update-goldens     bless what runs instead of comparing (refused with exit status 2 when the
                         CI environment variable is set)
    --golden-report DIR  write failure reports under DIR (default: pytest's temporary folder); a
                         folder of its own, as `collide2d check --report DIR` needs
    --golden-root DIR    the project folder holding scenarios/ and goldens/

Two scenario files with one name fail both their tests, as `collide2d check` refuses them, and
neither golden is written. A test function asks for the `golden_scenario` argument to be
parametrised over the scenario files, and calls the `golden_check` fixture with it. Each test
writes only its own scenario's golden and report folder, so `pytest -n auto` (pytest-xdist) has
no write races. The fixtures `golden_load` and `golden_simulate` give the scenario loader and the
simulator; a conftest can override them. The terminal summary lists the goldens written and the
goldens no scenario uses.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

from collide2d.runner.output import escape

# Every pytest run of the project loads this plugin: the harness (numpy, Pillow, the engine) is
# imported inside the hooks and fixtures that use it, so that it costs nothing until they run.

# user_properties keys a golden test records (they travel from xdist workers to the controller).
PROP_NAME = "golden_name"
PROP_BLESSED = "golden_blessed"


def pytest_addoption(parser) -> None:
    group = parser.getgroup("goldens", "collide2d golden regression")
    group.addoption(
        "--update-goldens",
        action="store_true",
        default=False,
        help="bless the goldens of the golden tests that run (never when CI is set)",
    )
    group.addoption(
        "--golden-report",
        metavar="DIR",
        default=None,
        help="write golden failure reports under DIR (default: pytest's temporary folder)",
    )
    group.addoption(
        "--golden-root",
        metavar="DIR",
        default=None,
        help="project folder holding scenarios/ and goldens/ (default: found upward from here)",
    )


def pytest_configure(config) -> None:
    if config.getoption("golden_report"):
        _check_report_option(config)
    if not config.getoption("update_goldens"):
        return
    from collide2d.runner.golden.store import ci_active

    if ci_active():
        pytest.exit(
            "--update-goldens: CI is set: goldens are never written in CI; "
            "bless locally and commit goldens/",
            returncode=2,
        )


def _check_report_option(config) -> None:
    """--golden-report DIR by the rule of `collide2d check --report DIR`: a folder of its own,
    neither the project folder, nor holding it, nor meeting one of its folders (exit status 2;
    runner.command.settings.Config.apart). A project that cannot be found is left to the golden
    tests, which fail saying why."""
    from collide2d.runner.command.settings import ConfigError, FolderClash
    from collide2d.runner.golden.store import GoldenError

    try:
        project = _project(config)
    except (GoldenError, ConfigError):
        return
    try:
        project.apart("report", config.getoption("golden_report"), "--golden-report")
    except FolderClash as exc:
        pytest.exit(f"collide2d: error: {exc}", returncode=2)


def _project(config):
    """The project's runner.command.settings.Config: --golden-root's, else the nearest one upward
    with a [tool.collide2d] table or a scenarios/ folder (GoldenError when there is neither)."""
    from collide2d.runner.command import settings
    from collide2d.runner.golden.store import find_root

    given = config.getoption("golden_root")
    if given:
        return settings.at(given)
    found = settings.find(config.invocation_params.dir)
    return found if found.file else settings.at(find_root(config.invocation_params.dir))


def _root(config) -> Path:
    return _project(config).root


def _scenario_files(project):
    from collide2d.runner.golden.store import scenario_files

    return scenario_files(project.root, project.value("scenarios"))


def pytest_collect_file(file_path, parent):
    """A scenario file in the scenarios folder of a project with a [tool.collide2d] table is one
    golden test."""
    if file_path.suffix not in (".yaml", ".yml"):
        return None
    from collide2d.runner.command import settings

    try:
        project = settings.find(file_path.parent)
    except settings.ConfigError:
        return None
    if project.file is None or file_path.parent != project.scenarios.resolve():
        return None
    return GoldenFile.from_parent(parent, path=file_path)


class GoldenFile(pytest.File):
    """A scenario file collected as a test module holding its one golden test."""

    def collect(self):
        yield GoldenItem.from_parent(self, name="golden")


class GoldenItem(pytest.Item):
    """The golden test of one scenario file: check it (or bless it with --update-goldens)."""

    def runtest(self) -> None:
        project = _project(self.config)
        check_golden(
            self,
            self.path,
            project,
            _default_load(project),
            _default_simulate(),
            lambda: _basetemp(self.config),
        )

    def repr_failure(self, excinfo):
        if isinstance(excinfo.value, pytest.fail.Exception):
            return str(excinfo.value)
        return super().repr_failure(excinfo)

    def reportinfo(self):
        return self.path, None, f"golden {self.path.stem}"


def pytest_generate_tests(metafunc) -> None:
    if "golden_scenario" not in metafunc.fixturenames:
        return
    from collide2d.runner.golden.store import GoldenError

    try:
        _root(metafunc.config)
    except GoldenError as exc:
        pytest.fail(str(exc), pytrace=False)
    params = [pytest.param(p, id=p.stem) for p in _scenario_files(_project(metafunc.config))]
    if not params:
        params = [pytest.param(None, id="no-scenarios")]
    metafunc.parametrize("golden_scenario", params)


@pytest.fixture(scope="session")
def golden_root(pytestconfig) -> Path:
    """The project folder holding scenarios/ and goldens/."""
    return _root(pytestconfig)


@pytest.fixture(scope="session")
def golden_load(pytestconfig):
    """The scenario loader: path -> Scenario (with the project's limits and model defaults)."""
    return _default_load(_project(pytestconfig))


@pytest.fixture(scope="session")
def golden_simulate():
    """The simulator, called as runner.run.simulate."""
    return _default_simulate()


def _default_load(project):
    from functools import partial

    from collide2d.runner.golden.cli import default_load

    return partial(default_load, **project.load_options())


def _default_simulate():
    from collide2d.runner.golden.cli import default_simulate

    return default_simulate


@pytest.fixture
def golden_check(request, golden_load, golden_simulate, tmp_path_factory):
    """check(path): run the scenario file `path` and compare it with its golden (or, with
    --update-goldens, bless it); fails the test with the text `collide2d check` prints."""
    project = _project(request.config)

    def check(path) -> None:
        if path is None:
            pytest.fail(f"no scenario files in {project.scenarios}", pytrace=False)
        check_golden(
            request.node, path, project, golden_load, golden_simulate, tmp_path_factory.getbasetemp
        )

    return check


def _basetemp(config) -> Path:
    """pytest's base temporary folder, for an Item (which has no fixtures of its own): the one the
    tmp_path_factory fixture uses when pytest keeps its factory on the config, else a new
    temporary folder (a pytest without that attribute still runs the golden tests)."""
    factory = getattr(config, "_tmp_path_factory", None)
    if factory is not None:
        return factory.getbasetemp()
    return Path(tempfile.mkdtemp(prefix="collide2d-golden-"))


def check_golden(node, path, project, load, simulate, basetemp) -> None:
    """The golden test of the scenario file `path` in `project` (a runner.command.settings.Config),
    run as the test `node`: check it, or bless it under --update-goldens; pytest.fail with the text
    `collide2d check` prints. `basetemp()`: the folder a failure's report goes under when no
    --golden-report is given."""
    from collide2d.runner.golden import bless_run, check_run, shown_path
    from collide2d.runner.golden.cli import run_scenario, scenario_errors, viewer_of
    from collide2d.runner.golden.store import GoldenError, GoldenStore

    config = node.config
    try:
        scenario = load(shown_path(path))
    except scenario_errors() as exc:
        _fail(str(exc))
    refusal = _same_name(config, project, load, Path(path), scenario.name)
    if refusal is not None:  # as `collide2d check` and `bless` refuse it: no golden is written
        _fail(refusal)
    node.user_properties.append((PROP_NAME, scenario.name))
    result = run_scenario(scenario, simulate)
    store = GoldenStore(project.root, project.value("goldens"))
    if config.getoption("update_goldens"):
        try:
            blessed = bless_run(scenario, result, store)
        except GoldenError as exc:  # a symbolic link in the way
            _fail(str(exc))
        node.user_properties.append((PROP_BLESSED, blessed.line()))
        return
    given = config.getoption("golden_report")
    report_dir = Path(given) if given else basetemp() / "golden-report"
    try:
        outcome = check_run(
            scenario, result, store, path=path, report_dir=report_dir, viewer=viewer_of(simulate)
        )
    except GoldenError as exc:  # the report folder refused (a symbolic link)
        _fail(str(exc))
    if not outcome.ok:
        _fail(outcome.message())


def _fail(text: str) -> None:
    """Fail the golden test with `text`, control characters spelled out (`escape.visible`): a
    name, a file name or a golden's text never reaches the terminal raw."""
    pytest.fail(escape.visible(text), pytrace=False)


# The names of the scenario files of the project's scenarios folder, read once a session.
_NAMES = pytest.StashKey[dict]()


def _same_name(config, project, load, path: Path, name: str) -> str | None:
    """The refusal of the scenario file `path` named `name` when another scenario file of the
    project has its name (the rule of `collide2d check`: runner.golden.store.same_names), else
    None. The other files' names are read once a session; a file that does not load is left to
    its own test."""
    from collide2d.runner.golden import shown_path
    from collide2d.runner.golden.cli import scenario_errors
    from collide2d.runner.golden.store import same_names

    cache = config.stash.setdefault(_NAMES, {})
    if project.root not in cache:
        names = {}
        for file in _scenario_files(project):
            try:
                names[file.resolve()] = (file, load(shown_path(file)).name)
            except scenario_errors():
                continue
        cache[project.root] = names
    named = dict(cache[project.root])
    named[path.resolve()] = (path, name)
    return same_names(named.values()).get(path)


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:
    reports = [
        r
        for key in ("passed", "failed")
        for r in terminalreporter.stats.get(key, [])
        if getattr(r, "when", None) == "call"
    ]
    props = [(k, v) for r in reports for k, v in r.user_properties]
    blessed = sorted(v for k, v in props if k == PROP_BLESSED)
    if blessed:
        terminalreporter.section("goldens written (--update-goldens)")
        for line in blessed:
            terminalreporter.write_line(line)
    names = {v for k, v in props if k == PROP_NAME}
    if not names:
        return
    from collide2d.runner.golden.store import GoldenError, GoldenStore

    try:
        project = _project(config)
    except GoldenError:
        return
    # Unused goldens are only known when every scenario ran.
    if len(names) == len(_scenario_files(project)):
        try:
            unused = GoldenStore(project.root, project.value("goldens")).unused(names)
        except GoldenError:  # goldens/ is a link: every golden test already failed saying so
            return
        if unused:
            terminalreporter.section("unused goldens")
            terminalreporter.write_line(
                f"no scenario uses: {', '.join(unused)}; remove them with: collide2d bless --prune"
            )
