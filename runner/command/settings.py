"""A project's `[tool.collide2d]` table in `pyproject.toml`: folders, limits and model defaults.

`find(start)` walks up from `start` (default: the current directory) to the nearest folder whose
`pyproject.toml` holds a `[tool.collide2d]` table, or, failing that, that has a `scenarios/`
folder (a project without the table keeps today's layout), and returns a `Config`: every setting
with its value and where it came from. The table (every key optional):

    [tool.collide2d]
    scenarios = "scenarios"   # scenario files (one golden test each)
    goldens = "goldens"       # golden folders
    report = "report"         # `collide2d check --report` with no folder named
    out = "out"               # `collide2d run`'s output folder
    threads = 2               # threads of the kernels that take them (read by `--threads`)
    jit = "auto"              # auto | on | off: compiled kernels (read by `--jit`; runner.lanes)

    [tool.collide2d.limits]   # any of the --max-* options, as max_objects = 5000, ...
    [tool.collide2d.model]    # kind, substeps, geometry, max_events_per_tick

Precedence: the command line, then the scenario file, then this table, then the defaults;
`collide2d config` prints each value and its source. A bad table is refused like a bad scenario:
`pyproject.toml:LINE:COL: error: ...` (exit 2), with a did-you-mean for a misspelt key. Folders are
relative to the project folder and must stay inside it; the four are apart: none is the project
folder, another's folder, or inside another (`Config.apart` holds a folder named on the command
line, as `check --report DIR`, to the same rule). Model settings have the bounds a scenario file's
`model` has (runner.scenario.load). Read with `tomllib` (Python 3.11+) or `tomli` (3.10).
"""

from __future__ import annotations

import difflib
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.parse import ScenarioError

PYPROJECT = "pyproject.toml"
TABLE = "tool.collide2d"
FOLDER_KEYS = {"scenarios": "scenarios", "goldens": "goldens", "report": "report", "out": "out"}
TOP_KEYS = (*FOLDER_KEYS, "threads", "jit", "limits", "model")
JIT_CHOICES = ("auto", "on", "off")
LIMIT_KEYS = tuple(Limits.__dataclass_fields__)
MODEL_KEYS = ("kind", "substeps", "geometry", "max_events_per_tick")
MODEL_CHOICES = {"kind": ("paper", "stepped", "exact"), "geometry": ("box", "exact")}

DEFAULT = "default"
COMMAND_LINE = "command line"


class ConfigError(ScenarioError):
    """The `[tool.collide2d]` table refused: str(err) is `PATH:LINE:COL: error: MESSAGE`."""


class ConfigErrors(ConfigError):
    """Every refusal of one table, in line order (`errors`), so that one run of a command shows
    them all; str(err) is one line each. As a ConfigError it is the first of them."""

    def __init__(self, errors: list[ConfigError]):
        first = errors[0]
        super().__init__(first.path, first.line, first.col, first.message)
        self.errors = list(errors)

    def __str__(self) -> str:
        return "\n".join(str(e) for e in self.errors)


class FolderClash(ValueError):
    """A folder named on the command line is the project folder, holds it, or meets one of the
    project's folders (`Config.apart`): str(err) is the message for the user."""


@dataclass(frozen=True)
class Setting:
    value: object
    source: str  # DEFAULT, COMMAND_LINE or "PATH [tool.collide2d]"


@dataclass
class Config:
    """The effective settings of one project folder (`root`); `file` is its pyproject.toml when
    that holds the table, else None. `settings` maps dotted names ("scenarios",
    "limits.max_objects", "model.geometry") to Settings; folders are relative to `root`."""

    root: Path
    file: Path | None
    settings: dict[str, Setting] = field(default_factory=dict)

    def value(self, key: str, default=None):
        s = self.settings.get(key)
        return default if s is None else s.value

    def folder(self, key: str) -> Path:
        """The folder setting `key` as a path under the root."""
        return self.root / self.value(key)

    @property
    def scenarios(self) -> Path:
        return self.folder("scenarios")

    @property
    def goldens(self) -> Path:
        return self.folder("goldens")

    def limits(self, given: dict | None = None) -> Limits:
        """The Limits in force: `given` (the command line's, None where not given) over the
        table's over the defaults."""
        values = {k: self.value(f"limits.{k}") for k in LIMIT_KEYS}
        values.update({k: v for k, v in (given or {}).items() if v is not None})
        return Limits(**{k: v for k, v in values.items() if v is not None})

    def model_defaults(self) -> dict:
        """The table's model settings ({} when none): the scenario loader's `defaults`."""
        return {k: self.value(f"model.{k}") for k in MODEL_KEYS if f"model.{k}" in self.settings}

    def load_options(self) -> dict:
        """The scenario loader's keyword arguments for what the table sets: `limits` when it
        sets any, `defaults` when it sets model settings ({} for a project without them)."""
        options = {}
        if any(k.startswith("limits.") for k in self.settings):
            options["limits"] = self.limits()
        if self.model_defaults():
            options["defaults"] = self.model_defaults()
        return options

    def apart(self, key: str, given, option: str) -> Path:
        """The folder `given` (named by the command-line `option` in place of the setting `key`),
        when it holds neither the project folder nor another of the project's folders and lies
        in none; FolderClash if not."""
        others = {k: self.folder(k) for k in FOLDER_KEYS if k != key}
        why = _clash(Path(given), self.root, others)
        if why is not None:
            raise FolderClash(f"{option} {given} {why}; name a folder of its own")
        return Path(given)

    def override(self, key: str, value) -> None:
        """Set `key` from the command line (when `value` is not None)."""
        if value is not None:
            self.settings[key] = Setting(value, COMMAND_LINE)

    def lines(self) -> list[str]:
        """`collide2d config`'s table: one line per setting, value and source."""
        rows = [("project", str(self.root), str(self.file) if self.file else "no [tool.collide2d]")]
        for key in (*FOLDER_KEYS, "threads", "jit"):
            s = self.settings.get(key, Setting(None, DEFAULT))
            unset = {"threads": "all cores", "jit": "auto"}.get(key, "-")
            rows.append((key, unset if s.value is None else _shown(s.value), s.source))
        defaults = Limits()
        for k in LIMIT_KEYS:
            s = self.settings.get(f"limits.{k}", Setting(getattr(defaults, k), DEFAULT))
            rows.append((f"limits.{k}", _shown(s.value), s.source))
        for k in MODEL_KEYS:
            s = self.settings.get(f"model.{k}", Setting(None, DEFAULT))
            rows.append((f"model.{k}", _shown(s.value), s.source))
        width = max(len(r[0]) for r in rows)
        vwidth = max(len(r[1]) for r in rows)
        return [f"{k:<{width}}  {v:<{vwidth}}  {src}" for k, v, src in rows]


def _shown(value) -> str:
    if value is None:
        return "(the scenario's, else the model's default)"
    if isinstance(value, int) and not isinstance(value, bool):
        return f"{value:,}"
    return str(value)


def find(start=None) -> Config:
    """The Config of the project at or above `start` (see the module docstring); with neither a
    table nor a `scenarios/` folder anywhere up, the defaults at `start`."""
    here = Path(start if start is not None else os.getcwd()).resolve()
    for folder in (here, *here.parents):
        pyproject = folder / PYPROJECT
        if pyproject.is_file():
            table = _table(pyproject)
            if table is not None:
                return _config(folder, pyproject, table)
        if (folder / FOLDER_KEYS["scenarios"]).is_dir():
            return _config(folder, None, {})
    return _config(here, None, {})


def at(root) -> Config:
    """The Config of the project folder `root` itself (as named by `--root`)."""
    root = Path(root).resolve()
    pyproject = root / PYPROJECT
    table = _table(pyproject) if pyproject.is_file() else None
    return _config(root, pyproject if table is not None else None, table or {})


def has_table(pyproject) -> bool:
    """Whether the file `pyproject` holds a `[tool.collide2d]` table (False if unreadable)."""
    try:
        return _table(Path(pyproject)) is not None
    except ConfigError:
        return False


def _toml():
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib


def parse(text: str, pyproject) -> dict:
    """The TOML document `text` (the file `pyproject`'s); a ConfigError where it is refused."""
    tomllib = _toml()
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        at = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        line, col = (int(at[1]), int(at[2])) if at else (1, 1)
        text = str(exc).split(" (at line")[0]
        raise ConfigError(str(pyproject), line, col, f"not valid TOML: {text}") from None


def _table(pyproject: Path) -> dict | None:
    try:
        text = pyproject.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(str(pyproject), 1, 1, f"cannot read the file: {exc}") from None
    data = parse(text, pyproject)
    table = data.get("tool", {}).get("collide2d") if isinstance(data.get("tool"), dict) else None
    if table is None:
        return None
    if not isinstance(table, dict):
        line = _line(pyproject, "collide2d")
        raise ConfigError(str(pyproject), line, 1, f"{TABLE} must be a table")
    return table


def _line(pyproject: Path, key: str) -> int:
    """The first line of the file that sets or opens `key` (1 if none): for error locations."""
    pattern = re.compile(rf"^\s*(\[+\s*)?[\w.\"]*\b{re.escape(key)}\b")
    try:
        for n, line in enumerate(pyproject.read_text(encoding="utf-8").splitlines(), start=1):
            if pattern.match(line):
                return n
    except OSError:
        pass
    return 1


def _config(root: Path, pyproject: Path | None, table: dict) -> Config:
    config = Config(root, pyproject)
    for key, default in FOLDER_KEYS.items():
        config.settings[key] = Setting(default, DEFAULT)
    if pyproject is None:
        return config
    source = f"{pyproject} [{TABLE}]"
    refused: list[ConfigError] = []  # every refusal of the table, all told at once

    def fail(key: str, message: str):
        return ConfigError(str(pyproject), _line(pyproject, key.split(".")[-1]), 1, message)

    def setting(name: str, check, *args) -> None:
        """settings[name] = check(*args) from the table, or its refusal kept."""
        try:
            config.settings[name] = Setting(check(*args), source)
        except ConfigError as err:
            refused.append(err)

    def known(keys, given: dict, where: str) -> None:
        for k in given:
            if k not in keys:
                near = difflib.get_close_matches(k, keys, n=1)
                hint = f"; did you mean '{near[0]}'?" if near else f"; expected {', '.join(keys)}"
                refused.append(fail(k, f"[{where}] has no setting '{k}'{hint}"))

    def whole(key: str, value, lo: int = 1, hi: int | None = None) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < lo:
            raise fail(key, f"{key} must be a whole number >= {lo}, not {_brief(value)}")
        if hi is not None and value > hi:
            raise fail(key, f"{key} must be at most {hi}, not {_brief(value)}")
        return value

    def choice(key: str, name: str, value, choices) -> str:
        if value not in choices:
            raise fail(key, f"{name} must be one of {' | '.join(choices)}, not {_brief(value)}")
        return value

    known(TOP_KEYS, table, TABLE)
    for key in FOLDER_KEYS:
        if key in table:
            setting(key, _folder, table[key], key, root, fail)
    if not refused:  # the folders are apart only once each is a folder of the project
        refused += _apart(config, table, fail)
    if "threads" in table:
        setting("threads", whole, "threads", table["threads"])
    if "jit" in table:
        setting("jit", choice, "jit", "jit", table["jit"], JIT_CHOICES)
    for section, keys in (("limits", LIMIT_KEYS), ("model", MODEL_KEYS)):
        given = table.get(section, {})
        if not isinstance(given, dict):
            refused.append(fail(section, f"[{TABLE}.{section}] must be a table"))
            continue
        known(keys, given, f"{TABLE}.{section}")
        for k, v in given.items():
            name = f"{section}.{k}"
            if k not in keys:
                continue
            if section == "model" and k in _model_bounds():  # a scenario file's own bounds
                setting(name, whole, name, v, *_model_bounds()[k])
            elif k in MODEL_CHOICES:
                setting(name, choice, k, name, v, MODEL_CHOICES[k])
            else:
                setting(name, whole, name, v)
    if refused:
        refused.sort(key=lambda e: (e.line, e.col))
        raise refused[0] if len(refused) == 1 else ConfigErrors(refused)
    return config


def _model_bounds() -> dict:
    """The whole-number model settings and their (lowest, highest): runner.scenario.load's, read
    when a table sets one (the scenario reader is not loaded for a project that sets none)."""
    from collide2d.runner.scenario.load import MODEL_BOUNDS

    return MODEL_BOUNDS


def _brief(value) -> str:
    """A value as a message shows it: a huge number by its digit count, long text cut."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**24:
        return f"a number of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _folder(value, key: str, root: Path, fail) -> str:
    if not isinstance(value, str) or not value.strip():
        raise fail(key, f"{key} must be a folder name (text), not {_brief(value)}")
    if any(ord(c) < 32 or ord(c) == 127 for c in value):
        raise fail(key, f"{key} = {_brief(value)} holds a control character; name a plain folder")
    path = Path(value)
    inside = (root / path).resolve()
    if path.is_absolute() or (inside != root and root not in inside.parents):
        raise fail(key, f"{key} = {value!r} leads outside the project folder {root}")
    return value


def _apart(config: Config, table: dict, fail) -> list:
    """The refusals (ConfigErrors) of each folder of the table that is the project folder or
    meets another (the same folder, or one inside the other), at the line of the setting the
    table gives (the later one when it gives both)."""
    refused = []
    given = [k for k in table if k in FOLDER_KEYS]  # in the file's order
    for i, key in enumerate(given):
        others = {k: config.folder(k) for k in FOLDER_KEYS if k not in table or k in given[:i]}
        why = _clash(config.folder(key), config.root, others)
        if why is not None:
            refused.append(
                fail(
                    key,
                    f"{key} = {_brief(table[key])} {why}; scenarios, goldens, report and out each "
                    "need a folder of their own inside the project",
                )
            )
    return refused


def _clash(path: Path, root: Path, others: dict) -> str | None:
    """Why the folder `path` cannot serve beside the project folder `root` and its folders
    `others` (setting -> path), or None when it is apart from them all."""
    path, root = path.resolve(), root.resolve()
    if path == root:
        return f"is the project folder {root}"
    if path in root.parents:
        return f"holds the project folder {root}"
    for key, other in others.items():
        other = other.resolve()
        shown = f"the {key} folder {_under(other, root)}"
        if path == other:
            return f"is {shown}"
        if other in path.parents:
            return f"is inside {shown}"
        if path in other.parents:
            return f"holds {shown}"
    return None


def _under(path: Path, root: Path) -> str:
    """`path` as shown in messages: relative to `root` when inside it, with a trailing slash."""
    try:
        return path.relative_to(root).as_posix() + "/"
    except ValueError:
        return path.as_posix() + "/"
