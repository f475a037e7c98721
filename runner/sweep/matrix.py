"""A sweep's matrix: scenarios times the values of each swept key times the seeds, as runs.

An `Axis` is one swept key with its values: a run setting (`model`, `fps`, `ticks`, `substeps`,
`geometry`) or a dotted scenario key (`world.width`, `generate.0.count`: mapping keys and list
indices from the top of the file). `parse_set` reads `--set KEY=V1,V2,...` (values are YAML, split
on the commas outside brackets and quotes, so `--set generate.0.size=[10,10],[20,20]` and
`--set objects.0.name="a, b",c` work), `parse_seeds` reads `--seeds 1-100` (also `7` and `1-5,9`).
The runs are the product of every axis and seed for each scenario: `choices` gives each combination
of the axes' values, `combo_of` loads it in full as a `Combo` (the runs of every seed share it;
`runner.sweep.plan` checks the seeds), and `load_run` loads one run (a located `ScenarioError`
naming the run's values when one is refused). A setting the run's model
does not take (`substeps` off `stepped`; `substeps` and `geometry` under `paper`) is left out and
the runs it would have told apart count once. A seed goes to every `generate` block of the file.

The model, substeps and geometry become the scenario's `model` entry (the file's own settings are
kept when it names the same kind); `fps` and `ticks` go in as the loader's overrides (so a
`duration` is counted again); dotted keys and seeds replace nodes of the composed YAML tree (or add
them where the file has none), placed at the node they replace, so the loader checks the result
exactly like a file.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

import yaml

from collide2d.engine.models import names, names_for, options_of
from collide2d.runner.scenario import parse
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.load import Scenario, ScenarioError, load
from collide2d.runner.scenario.objects import MAX_SEED

RUN_KEYS = ("model", "fps", "ticks", "substeps", "geometry")
MAX_RUNS = 1_000_000  # runs in one sweep
_SEGMENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*|[0-9]+")
_MAP = parse.CORE_TAG + "map"
_STR = parse.CORE_TAG + "str"
_INT = parse.CORE_TAG + "int"


class SweepError(Exception):
    """A sweep refused before anything ran (bad --set, --seeds, a missing key); str is the
    message, printed as `collide2d: error: MESSAGE`."""


@dataclass(frozen=True)
class Axis:
    """One swept key: its values as YAML nodes and as written (for tables)."""

    key: str
    nodes: tuple
    texts: tuple[str, ...]
    origin: str  # where it was given: "--set KEY=..." or "FILE:LINE:COL"


def split_values(text: str) -> list[str]:
    """`a,[1,2],'b, c'` -> ["a", "[1,2]", "'b, c'"]: commas inside brackets, braces or a quoted
    YAML text stay. A quote opens a quoted text where YAML would read one (at the start of a value
    or after `[`, `{`, `,` or `:`), so an apostrophe inside a word (`it's`) is just a character;
    `''` inside single quotes and a backslash inside double quotes escape as in YAML."""
    out, depth, start = [], 0, 0
    quote, last, i = "", "", 0  # the open quote; the value's last character outside spaces
    while i < len(text):
        ch = text[i]
        if quote:
            if quote == '"' and ch == "\\":
                i += 1  # the escaped character
            elif quote == "'" and ch == "'" and text[i + 1 : i + 2] == "'":
                i += 1  # '' is one quote
            elif ch == quote:
                quote = ""
        elif ch in "'\"" and last in ("", "[", "{", ",", ":"):
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            out.append(text[start:i])
            start, last = i + 1, ""
            i += 1
            continue
        if not ch.isspace():
            last = ch
        i += 1
    out.append(text[start:])
    return [v.strip() for v in out]


def check_key(key: str, origin: str) -> None:
    """SweepError unless `key` is a run setting or a dotted path of names and indices."""
    if key in RUN_KEYS:
        return
    parts = key.split(".")
    if not all(_SEGMENT.fullmatch(p) for p in parts) or parts[0].isdigit():
        raise SweepError(
            f"{origin}: {key!r} is not a key to sweep: one of {', '.join(RUN_KEYS)} or a dotted "
            "scenario key such as world.width or generate.0.count"
        )
    if parts[0] in ("model", "ticks", "duration") or key == "world.fps":
        raise SweepError(
            f"{origin}: sweep {parts[0]!r} with the run settings ({', '.join(RUN_KEYS)})"
        )


def value_node(text: str, origin: str, limits: Limits):
    """One value written on the command line as a YAML node (read by the safe loader)."""
    if text == "":
        raise SweepError(f"{origin}: an empty value")
    try:
        node = parse.compose(text, origin, limits)
    except ScenarioError as exc:
        raise SweepError(f"{origin}: {text!r} is not a YAML value: {exc.message}") from None
    return node


def parse_set(option: str, limits: Limits | None = None) -> Axis:
    """`KEY=V1,V2,...` as an Axis (SweepError if malformed)."""
    limits = limits or Limits()
    origin = f"--set {option}"
    key, eq, rest = option.partition("=")
    key = key.strip()
    if not eq or not key:
        raise SweepError(f"{origin}: expected KEY=V1,V2,... (for example fps=10,30,60)")
    check_key(key, origin)
    texts = split_values(rest)
    nodes = tuple(value_node(t, origin, limits) for t in texts)
    return Axis(key, nodes, tuple(texts), origin)


def parse_seeds(text: str, origin: str = "--seeds") -> tuple[int, ...]:
    """`1-100`, `7`, `1-5,9` -> the seeds in increasing order (SweepError if malformed)."""
    seeds: set[int] = set()
    for part in text.split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if not m:
            raise SweepError(f"{origin} {text}: expected A-B, A, or a list of them (1-5,9)")
        a = int(m.group(1))
        b = int(m.group(2)) if m.group(2) is not None else a
        if b < a or b > MAX_SEED:
            raise SweepError(
                f"{origin} {text}: {part.strip()} is not a range of seeds 0 to {MAX_SEED}"
            )
        if b - a + len(seeds) >= MAX_RUNS:
            raise SweepError(f"{origin} {text}: more than {MAX_RUNS:,} seeds")
        seeds.update(range(a, b + 1))
    return tuple(sorted(seeds))


def _scalar(text: str, mark, tag: str = _STR):
    return yaml.ScalarNode(tag, text, start_mark=mark, end_mark=mark)


def _relocated(node, mark):
    """A copy of `node` whose every mark is `mark` (so the loader's errors point at the file)."""
    if isinstance(node, yaml.ScalarNode):
        return yaml.ScalarNode(node.tag, node.value, mark, mark, node.style)
    if isinstance(node, yaml.SequenceNode):
        items = [_relocated(n, mark) for n in node.value]
        return yaml.SequenceNode(node.tag, items, mark, mark, node.flow_style)
    pairs = [(_relocated(k, mark), _relocated(v, mark)) for k, v in node.value]
    return yaml.MappingNode(node.tag, pairs, mark, mark, node.flow_style)


def _find(mapping, key: str):
    """The index of `key` among a mapping node's pairs, or None."""
    for i, (k, _v) in enumerate(mapping.value):
        if isinstance(k, yaml.ScalarNode) and k.value == key:
            return i
    return None


def set_path(root, path: list[str], value, shown: str) -> None:
    """Put `value` (a node) at the dotted `path` of the tree: replace the node there, or add the
    key (and mappings on the way) where the file has none. SweepError where the path cannot go."""
    node = root
    for depth, part in enumerate(path):
        last = depth == len(path) - 1
        where = ".".join(path[: depth + 1])
        if isinstance(node, yaml.SequenceNode):
            if not part.isdigit() or int(part) >= len(node.value):
                raise SweepError(f"{shown}: the scenario has no {where} ({len(node.value)} items)")
            i = int(part)
            if last:
                node.value[i] = _relocated(value, node.value[i].start_mark)
                return
            node = node.value[i]
        elif isinstance(node, yaml.MappingNode):
            if part.isdigit():
                raise SweepError(
                    f"{shown}: {'.'.join(path[:depth]) or 'the scenario'} is a mapping"
                )
            i = _find(node, part)
            if i is None:
                child = value if last else yaml.MappingNode(_MAP, [], flow_style=True)
                child = _relocated(child, node.start_mark)
                node.value.append((_scalar(part, node.start_mark), child))
                if last:
                    return
                node = child
                continue
            if last:
                key, old = node.value[i]
                node.value[i] = (key, _relocated(value, old.start_mark))
                return
            node = node.value[i][1]
        else:
            raise SweepError(f"{shown}: {'.'.join(path[:depth])} is a single value, not a mapping")


def _model_node(root, kind: str, settings: dict):
    """The scenario's `model` entry as a mapping for `kind`: the file's own settings when it
    names the same kind, then `settings` (substeps, geometry) over them."""
    i = _find(root, "model")
    mark = root.value[i][1].start_mark if i is not None else root.start_mark
    pairs = []
    if i is not None:
        old = root.value[i][1]
        if isinstance(old, yaml.MappingNode):
            k = _find(old, "kind")
            if k is not None and old.value[k][1].value == kind:
                pairs = [p for p in old.value if p[0].value not in settings]
        elif isinstance(old, yaml.ScalarNode) and old.value == kind:
            pairs = [(_scalar("kind", mark), _scalar(kind, mark))]
    if not any(p[0].value == "kind" for p in pairs):
        pairs.insert(0, (_scalar("kind", mark), _scalar(kind, mark)))
    for key, node in settings.items():
        pairs.append((_scalar(key, mark), _relocated(node, mark)))
    node = yaml.MappingNode(_MAP, pairs, mark, mark, True)
    if i is None:
        root.value.append((_scalar("model", mark), node))
    else:
        root.value[i] = (root.value[i][0], node)


def _edit(values: dict, seed: int | None, shown: str):
    """The edit of a composed scenario tree for one run (see the module docstring)."""

    def edit(root):
        if not isinstance(root, yaml.MappingNode):
            return root  # the loader refuses it with its own message
        for key, node in values.items():
            if key not in RUN_KEYS:
                set_path(root, key.split("."), node, f"{shown} {key}")
        if "model" in values:
            settings = {k: values[k] for k in ("substeps", "geometry") if k in values}
            _model_node(root, parse.value(values["model"]), settings)
        if seed is not None:
            i = _find(root, "generate")
            blocks = root.value[i][1] if i is not None else None
            if not isinstance(blocks, yaml.SequenceNode) or not blocks.value:
                raise SweepError(f"{shown}: --seeds needs a generate block, and the file has none")
            for k in range(len(blocks.value)):
                set_path(
                    root,
                    ["generate", str(k), "seed"],
                    _scalar(str(seed), root.start_mark, _INT),
                    shown,
                )
        return root

    return edit


def _sort_value(text: str):
    """Numbers in order of size, then texts in alphabetical order."""
    try:
        return (0, float(text), text)
    except ValueError:
        return (1, 0.0, text)


def seed_key(seed: int) -> tuple:
    """A seed's place in a run's sort key."""
    return (0, float(seed), str(seed))


def _file_model(path: str, seed: int | None, limits: Limits) -> str:
    """The model of the file itself (as loaded with the sweep's first seed, if any: the file's
    own seed need not place its objects)."""
    said = f"in the sweep run seed={seed}" if seed is not None else path
    try:
        return load(path, limits=limits, edit=_edit({}, seed, said)).model
    except ScenarioError as exc:
        raise ScenarioError(exc.path, exc.line, exc.col, f"{said}: {exc.message}") from None


def check_axes(scenarios: list[str], axes: list[Axis], seeds) -> int:
    """The runs of the matrix before settings a model does not take count once (SweepError for
    a key swept twice, a value given twice, an unknown model, more than MAX_RUNS runs)."""
    keys = [a.key for a in axes]
    repeated = [k for k in keys if keys.count(k) > 1]
    if repeated:
        raise SweepError(f"{repeated[0]} is swept twice; give its values once")
    for axis in axes:
        if len(set(axis.texts)) != len(axis.texts):
            raise SweepError(f"{axis.origin}: a value is given twice")
        if axis.key == "model":
            for node, text in zip(axis.nodes, axis.texts, strict=True):
                known = names_for(parse.value(node)) if isinstance(node, yaml.ScalarNode) else ()
                if not isinstance(node, yaml.ScalarNode) or parse.value(node) not in known:
                    raise SweepError(
                        f"{axis.origin}: unknown model {text!r}; expected {' | '.join(names())}"
                    )
    count = 1
    for axis in axes:
        count *= len(axis.texts)
    count *= len(scenarios) * (len(seeds) if seeds else 1)
    if count > MAX_RUNS:
        raise SweepError(f"the sweep has {count:,} runs, more than {MAX_RUNS:,}")
    return count


def choices(path: str, axes: list[Axis], seed: int | None, limits: Limits):
    """Each combination of the axes' values for the scenario at `path`: {key: (node, text)},
    without the settings its model does not take (see the module docstring)."""
    base_model = _file_model(path, seed, limits)
    for combo in itertools.product(*(range(len(a.texts)) for a in axes)):
        chosen = {a.key: (a.nodes[i], a.texts[i]) for a, i in zip(axes, combo, strict=True)}
        model = parse.value(chosen["model"][0]) if "model" in chosen else base_model
        for key in ("substeps", "geometry"):
            if key in chosen and key not in options_of(model):
                del chosen[key]  # this model does not take it: the runs count once
        yield chosen, model


@dataclass(frozen=True, eq=False)
class Combo:
    """One scenario file with one value of each swept key: the runs of every seed share it.

    `head` and `tail` are a run's sort key before and after its seed (the scenario's name and the
    dotted keys' values; the run settings), `params` its columns but the seed, `ref` what an
    `exact` run must share with it, besides the seed, to be its reference (`runner.sweep.results`).
    """

    path: str
    values: dict  # key -> YAML node, as the edit puts them in
    overrides: dict  # fps, ticks: the loader's overrides
    shown: tuple[str, ...]  # KEY=VALUE of each swept key, for messages
    params: dict
    head: tuple
    tail: tuple
    ref: tuple


def load_run(combo: Combo, seed: int | None, limits: Limits) -> Scenario:
    """The scenario of the run of `combo` with `seed`, loaded and checked in full (a located
    ScenarioError naming the run's values when refused)."""
    said = list(combo.shown) + ([f"seed={seed}"] if seed is not None else [])
    shown = f"in the sweep run {', '.join(said) or combo.path}"
    try:
        return load(
            combo.path,
            overrides=combo.overrides,
            limits=limits,
            edit=_edit(combo.values, seed, shown),
        )
    except ScenarioError as exc:
        raise ScenarioError(exc.path, exc.line, exc.col, f"{shown}: {exc.message}") from None
    except SweepError as exc:
        raise SweepError(f"{combo.path}: {exc}") from None


def combo_of(path, chosen, model, dotted, seed, limits) -> tuple[Combo, Scenario]:
    """The Combo of one choice of values for `path`, and its run with `seed` loaded in full."""
    values = {k: node for k, (node, _t) in chosen.items()}
    if "model" not in values and any(k in values for k in ("substeps", "geometry")):
        values["model"] = _scalar(model, None)
    overrides = {}
    for key in ("fps", "ticks"):
        if key in values:
            v = parse.value(values[key]) if isinstance(values[key], yaml.ScalarNode) else None
            overrides[key] = v if isinstance(v, int) and not isinstance(v, bool) else chosen[key][1]
    shown = tuple(f"{k}={t}" for k, (_n, t) in chosen.items())
    draft = Combo(path, values, overrides, shown, {}, (), (), ())
    scenario = load_run(draft, seed, limits)
    params = {"scenario": scenario.name}
    head: list = [scenario.name]
    for axis in dotted:
        text = chosen[axis.key][1]
        params[axis.key] = text
        head.append(_sort_value(text))
    takes = options_of(scenario.model)
    settings = {
        "model": scenario.model,
        "fps": str(scenario.world.fps),
        "ticks": str(scenario.ticks),
        "substeps": str(scenario.substeps) if "substeps" in takes else "",
        "geometry": scenario.geometry if scenario.model != "paper" else "",
    }
    params.update(settings)
    tail = tuple(_sort_value(settings[k]) for k in RUN_KEYS)
    ref = (tuple(head), settings["fps"], settings["ticks"])
    combo = Combo(path, values, overrides, shown, params, tuple(head), tail, ref)
    return combo, scenario


def columns(axes: list[Axis], seeds) -> list[str]:
    """The parameter columns of the results: scenario, dotted keys, seed, the run settings."""
    return (
        ["scenario"]
        + [a.key for a in axes if a.key not in RUN_KEYS]
        + (["seed"] if seeds else [])
        + list(RUN_KEYS)
    )
