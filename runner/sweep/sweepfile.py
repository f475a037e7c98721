"""Sweep files: the matrix of `collide2d sweep` kept in YAML, read like scenarios (located errors).

    sweep: 1                                 # marks a sweep file; the format version
    scenarios: [paper_fifty_boxes.yaml]      # relative to the sweep file's folder
    set:
      model: [paper, stepped, exact]         # run settings and dotted scenario keys, as --set
      fps: [10, 30, 60]
      world.width: [320, 640]
    seeds: 1-20                              # or 7, or [1, 2, 3], as --seeds

`is_sweep_file(path)` tells a sweep file from a scenario (a `.yaml` whose top level has `sweep`);
`read(path)` returns (scenario paths, axes, seeds), every problem a `ScenarioError`
`FILE:LINE:COL: error: MESSAGE` at its node. `--set` and `--seeds` on the command line replace the
file's values of the same key.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from collide2d.runner.scenario import parse
from collide2d.runner.scenario.limits import Limits
from collide2d.runner.scenario.nodes import Nodes
from collide2d.runner.sweep.matrix import Axis, SweepError, check_key, parse_seeds

FORMAT_VERSION = 1
KEYS = ("sweep", "scenarios", "set", "seeds")


def is_sweep_file(path: str, limits: Limits | None = None) -> bool:
    """True when the file's top level is a mapping with a `sweep` key (else it is a scenario)."""
    try:
        text, _digest = parse.read_file(path, limits or Limits())
        root = parse.compose(text, path, limits or Limits())
    except parse.ScenarioError:
        return False
    return isinstance(root, yaml.MappingNode) and any(
        isinstance(k, yaml.ScalarNode) and k.value == "sweep" for k, _v in root.value
    )


def _shown(node) -> str:
    """A value as written in flow style: `12`, `[10, 10]`, `{x: 1}`."""
    if isinstance(node, yaml.ScalarNode):
        return node.value
    if isinstance(node, yaml.SequenceNode):
        return "[" + ", ".join(_shown(n) for n in node.value) + "]"
    return "{" + ", ".join(f"{_shown(k)}: {_shown(v)}" for k, v in node.value) + "}"


def _pairs(nodes: Nodes, node) -> list:
    """[(key, key node, value node)] of the `set` mapping: names, each once."""
    if not isinstance(node, yaml.MappingNode):
        shown = parse.describe(node)
        raise nodes.error(node, f"set must be a mapping of keys to values, not {shown}")
    out, seen = [], set()
    for knode, vnode in node.value:
        key = nodes.string(knode, "a key of set")
        if key in seen:
            raise nodes.error(knode, f"duplicate key '{key}' in set")
        seen.add(key)
        out.append((key, knode, vnode))
    return out


def read(path: str, limits: Limits | None = None):
    """(scenario paths, [Axis], seeds or None) of the sweep file at `path`."""
    limits = limits or Limits()
    text, _digest = parse.read_file(path, limits)
    root = parse.compose(text, path, limits)
    nodes = Nodes(path)
    top = nodes.mapping(root, "the sweep file", KEYS)
    version = nodes.scalar(top["sweep"][1], "sweep")
    if version != FORMAT_VERSION or isinstance(version, bool):
        raise nodes.error(top["sweep"][1], f"sweep must be {FORMAT_VERSION}, the format version")
    if "scenarios" not in top:
        raise nodes.error(root, "a sweep file needs 'scenarios:', a list of scenario files")
    here = Path(path).parent
    scenarios = []
    for node in nodes.seq(top["scenarios"][1], "scenarios", min_len=1):
        name = nodes.string(node, "a scenario")
        file = here / name
        if not file.is_file():
            raise nodes.error(node, f"no scenario file {name!r} (looked for {file})")
        scenarios.append(str(file))
    axes = []
    if "set" in top:
        for key, knode, vnode in _pairs(nodes, top["set"][1]):
            where = f"{path}:{knode.start_mark.line + 1}:{knode.start_mark.column + 1}"
            try:
                check_key(key, f"set {key}")
            except SweepError as exc:
                raise nodes.error(knode, str(exc)) from None
            values = vnode.value if isinstance(vnode, yaml.SequenceNode) else [vnode]
            if not values:
                raise nodes.error(vnode, f"set {key} has no values")
            axes.append(Axis(key, tuple(values), tuple(_shown(v) for v in values), where))
    seeds = None
    if "seeds" in top:
        node = top["seeds"][1]
        items = node.value if isinstance(node, yaml.SequenceNode) else [node]
        texts = [str(nodes.scalar(n, "seeds")) for n in items]
        try:
            seeds = parse_seeds(",".join(texts), "seeds")
        except SweepError as exc:
            raise nodes.error(node, str(exc)) from None
    return scenarios, axes, seeds
