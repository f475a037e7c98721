"""The generated reference pages: each is made from the code it describes, on every docs build.

`commands_page` walks the argument parser of `collide2d` (runner.command.main.build_parser: every
command, every option with its help, choices and default), `schema_page` the scenario format's
JSON Schema (runner.scenario.schema.json_schema), `settings_page` the keys of a project's
`[tool.collide2d]` table (runner.command.settings, with the limits' defaults from
runner.scenario.limits) and `exit_statuses_page` the constants of runner.command.exitcodes with
their comments. Each returns Markdown; the hooks (docgen/hooks.py) add it to the site.
"""

from __future__ import annotations

import argparse
import ast
import io
import json
import tokenize
from pathlib import Path

GENERATED = (
    "<!-- Generated at build time by docgen/reference.py from {source}; do not edit. -->\n\n"
)


def cell(text: str) -> str:
    """Text made safe for one Markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|")


# ---------------------------------------------------------------------------------------------
# Commands, from the argument parser


def _help(action: argparse.Action, prog: str) -> str:
    text = action.help or ""
    if "%(" in text:
        params = {**vars(action), "prog": prog}
        if params.get("choices") is not None:
            params["choices"] = ", ".join(str(c) for c in params["choices"])
        text = text % params
    return text


def _option(action: argparse.Action) -> str:
    if not action.option_strings:
        name = action.metavar or action.dest
        return f"`{name.upper() if name == action.dest else name}`"
    if action.nargs == 0:
        return " / ".join(f"`{s}`" for s in action.option_strings)
    if action.metavar is not None:
        metavar = action.metavar
    elif action.choices is not None:
        metavar = "{" + ",".join(str(c) for c in action.choices) + "}"
    else:
        metavar = action.dest.upper()
    if action.nargs == "?":
        metavar = f"[{metavar}]"
    elif action.nargs in ("*", "+"):
        metavar = f"{metavar}..."
    return " / ".join(f"`{s} {metavar}`" for s in action.option_strings)


def _options_table(actions, prog: str) -> list[str]:
    positional = all(not a.option_strings for a in actions)
    rows = [f"| {'argument' if positional else 'option'} | meaning |", "| --- | --- |"]
    for action in actions:
        if isinstance(action, argparse._HelpAction) or action.help == argparse.SUPPRESS:
            continue
        meaning = _help(action, prog)
        if action.choices is not None and action.option_strings:
            choices = ", ".join(f"`{c}`" for c in action.choices)
            meaning = f"{meaning} (one of {choices})" if meaning else f"one of {choices}"
        rows.append(f"| {_option(action)} | {cell(meaning)} |")
    return rows if len(rows) > 2 else []


def command_parsers() -> tuple[argparse.ArgumentParser, dict, dict]:
    """The `collide2d` parser, its subcommands' parsers by name and their one-line helps."""
    from collide2d.runner.command.main import build_parser

    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    helps = {choice.dest: choice.help for choice in sub._choices_actions}
    return parser, dict(sub.choices), helps


def commands_page() -> str:
    parser, commands, helps = command_parsers()
    out = [
        GENERATED.format(source="the argument parser, runner/command/main.py: build_parser"),
        "# Commands and options",
        "",
        "Every command of `collide2d` (also `python -m collide2d`) and every option, as"
        " `collide2d COMMAND --help` prints them. How the settings combine, the exit statuses"
        " and Ctrl-C are in [Command line](../command-line.md).",
        "",
        "```text",
        parser.format_usage().strip(),
        "```",
        "",
        "| command | does |",
        "| --- | --- |",
    ]
    for name in commands:
        out.append(f"| [`{name}`](#{name}) | {cell(helps.get(name, ''))} |")
    out.append("")
    for name, sub in commands.items():
        summary = helps.get(name, "")
        out += [f"## {name}", "", f"{summary[:1].upper()}{summary[1:]}.", ""]
        out += ["```text", sub.format_usage().strip(), "```", ""]
        if sub.description:
            if isinstance(sub.formatter_class, type) and issubclass(
                sub.formatter_class, argparse.RawDescriptionHelpFormatter
            ):
                out += ["```text", sub.description.rstrip(), "```", ""]
            else:
                out += [" ".join(sub.description.split()), ""]
        for group in sub._action_groups:
            rows = _options_table(group._group_actions, sub.prog)
            if not rows:
                continue
            title = group.title
            if title in ("options", "optional arguments"):
                title = "options"
            out += [f"**{title}**", "", *rows, ""]
    return "\n".join(out)


# ---------------------------------------------------------------------------------------------
# The scenario format, from its JSON Schema


def _number(value) -> str:
    if isinstance(value, float) and value.is_integer() and abs(value) >= 1e6:
        return f"{value:.0e}".replace("e+", "e")
    if isinstance(value, int) and abs(value) >= 10_000:
        return f"{value:,}"
    return str(value)


def _anchor(ref: str) -> str:
    return ref.rsplit("/", 1)[-1]


def describe(node: dict) -> str:
    """A short text of what a schema node accepts."""
    if "$ref" in node:
        name = _anchor(node["$ref"])
        return f"[{name}](#{name})"
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        values = node["enum"]
        if len(values) > 12:
            return f"one of {len(values)} names"
        return " | ".join(f"`{v}`" for v in values)  # cell() escapes the bars
    for key in ("anyOf", "oneOf"):
        if key in node:
            return " or ".join(describe(n) for n in node[key])
    kind = node.get("type")
    if kind == "array":
        items = describe(node.get("items", {}))
        low, high = node.get("minItems"), node.get("maxItems")
        if low is not None and low == high:
            return f"{low} × ({items})"
        count = f", at least {low}" if low else ""
        return f"list of ({items}){count}"
    if kind == "object" and "properties" in node:
        keys = ", ".join(f"`{k}`" for k in node["properties"])
        return f"mapping of {keys}"
    text = {"integer": "whole number", "number": "number", "string": "text"}.get(kind, kind or "")
    text = text or "any"
    bounds = []
    if "minimum" in node:
        bounds.append(f">= {_number(node['minimum'])}")
    if "exclusiveMinimum" in node:
        bounds.append(f"> {_number(node['exclusiveMinimum'])}")
    if "maximum" in node:
        bounds.append(f"<= {_number(node['maximum'])}")
    if "maxLength" in node:
        bounds.append(f"at most {node['maxLength']} characters")
    if "pattern" in node:
        bounds.append(f"matching `{node['pattern']}`")
    return f"{text} {', '.join(bounds)}" if bounds else text


def _keys_table(node: dict, top: bool = False) -> list[str]:
    required = set(node.get("required", ()))
    rows = ["| key | required | value | description |", "| --- | --- | --- | --- |"]
    for key, sub in node.get("properties", {}).items():
        value = describe(sub)
        if top and sub.get("type") == "object" and "properties" in sub:
            value = f"mapping: [{key}](#{key})"  # a section of its own below
        rows.append(
            f"| `{key}` | {'yes' if key in required else ''} | {cell(value)} "
            f"| {cell(sub.get('description', ''))} |"
        )
    return rows


def _section(title: str, node: dict, top: bool = False) -> list[str]:
    out = [f"## {title}", ""]
    if node.get("description"):
        text = node["description"].rstrip(".")
        out += [text[:1].upper() + text[1:] + ".", ""]
    variants = node.get("oneOf") or node.get("anyOf")
    if "properties" in node:
        out += [*_keys_table(node, top), ""]
        if node.get("additionalProperties") is False:
            out += ["Any other key is refused.", ""]
    elif variants and any("properties" in v for v in variants):
        for variant in variants:
            if "properties" not in variant:
                out += [f"- or {describe(variant)}", ""]
                continue
            shape = variant["properties"].get("shape", {}).get("const")
            label = f"`shape: {shape}`" if shape else "mapping"
            out += [f"**{label}**", "", *_keys_table(variant), ""]
    else:
        out += [f"Accepts {describe(node)}.", ""]
        if "enum" in node.get("anyOf", [{}])[0] and len(node["anyOf"][0]["enum"]) > 12:
            names = ", ".join(f"`{v}`" for v in node["anyOf"][0]["enum"])
            out += [f"The names: {names}.", ""]
    return out


def schema_page() -> str:
    from collide2d.runner.scenario.schema import json_schema

    schema = json_schema()
    out = [
        GENERATED.format(source="the JSON Schema, runner/scenario/schema.py: json_schema"),
        "# Scenario schema",
        "",
        "Every key of a scenario file, from the JSON Schema that `collide2d schema` prints"
        f" ({schema['$schema'].rsplit('/', 2)[-2]} draft). The schema states the shape of a"
        " file; what it cannot state (the limits, objects inside the world and apart, the paper"
        " model's velocities, frames up to `ticks`, convex polygons) only the loader checks:"
        " [Scenario format](../scenario-format.md) gives those rules and the defaults.",
        "",
    ]
    out += _section("Top level", schema, top=True)
    if "not" in schema and "required" in schema["not"]:
        keys = " and ".join(f"`{k}`" for k in schema["not"]["required"])
        out += [f"{keys} exclude each other.", ""]
    for key, sub in schema["properties"].items():
        if sub.get("type") == "object" and "properties" in sub:
            out += _section(key, sub)
    for name, sub in schema.get("$defs", {}).items():
        out += _section(name, sub)
    out += [
        "## The schema itself",
        "",
        "`collide2d schema > collide2d.schema.json` writes it for an editor (for example the"
        " YAML language server: `# yaml-language-server: $schema=collide2d.schema.json` on a"
        " scenario's first line).",
        "",
    ]
    return "\n".join(out)


# ---------------------------------------------------------------------------------------------
# [tool.collide2d], from the settings reader and the limits


def settings_page() -> str:
    from collide2d.runner.command import settings
    from collide2d.runner.scenario.limits import Limits

    _parser, commands, _helps = command_parsers()
    options = {}  # a setting's dest: the first command that takes it, as `COMMAND --flag`
    for name, sub in commands.items():
        for action in sub._actions:
            if action.dest in ("scenarios",):  # bench's own folder of scenes, not the setting
                continue
            for flag in action.option_strings[:1]:
                options.setdefault(action.dest, f"{name} {flag}")
    limits = Limits()
    out = [
        GENERATED.format(source="runner/command/settings.py and runner/scenario/limits.py"),
        "# Project settings: `[tool.collide2d]`",
        "",
        "A project is the nearest folder upward whose `pyproject.toml` holds a"
        " `[tool.collide2d]` table (or, without one, that has a `scenarios/` folder)."
        " `collide2d init` writes the table; `collide2d config` prints every effective value"
        " and where it came from. Every key is optional. A setting comes from the first of:"
        " the command line, the scenario file, this table, the defaults. A misspelt key or a"
        " bad value is refused at its line, `pyproject.toml:LINE:COL: error: ...` (exit 2),"
        " with a did-you-mean.",
        "",
        "## `[tool.collide2d]`",
        "",
        "| key | default | command-line option |",
        "| --- | --- | --- |",
    ]
    for key, default in settings.FOLDER_KEYS.items():
        out.append(f"| `{key}` | `\"{default}\"` | {_flag(options, key)} |")
    out.append(f"| `threads` | every core | {_flag(options, 'threads')} |")
    choices = " \\| ".join(f"`\"{c}\"`" for c in settings.JIT_CHOICES)
    out.append(f"| `jit` | `\"auto\"` ({choices}) | {_flag(options, 'jit')} |")
    out += [
        "",
        "The four folders are relative to the project folder and stay inside it, apart: none is"
        " the project folder itself, another's folder or inside another. A folder named on the"
        " command line in their place (`run --out DIR`, `check --report DIR`,"
        " `pytest --golden-report DIR`) obeys the same rule.",
        "",
        "## `[tool.collide2d.limits]`",
        "",
        "Any of the [limits](../limits.md#limits):",
        "",
        "| key | default | command-line option |",
        "| --- | --- | --- |",
    ]
    for key in settings.LIMIT_KEYS:
        out.append(f"| `{key}` | {getattr(limits, key):,} | {_flag(options, key)} |")
    out += [
        "",
        "## `[tool.collide2d.model]`",
        "",
        "Model settings for the scenarios that give none (the bounds of a scenario's"
        " [`model`](../scenario-format.md#model)):",
        "",
        "| key | values |",
        "| --- | --- |",
    ]
    bounds = settings._model_bounds()
    for key in settings.MODEL_KEYS:
        if key in settings.MODEL_CHOICES:
            values = " \\| ".join(f"`\"{c}\"`" for c in settings.MODEL_CHOICES[key])
        else:
            low, high = bounds[key]
            values = f"whole number {low:,} to {high:,}"
        out.append(f"| `{key}` | {values} |")
    out += ["", "## An example", "", "```toml", _example_table(), "```", ""]
    return "\n".join(out)


def _flag(options: dict, dest: str) -> str:
    flag = options.get(dest)
    return f"`{flag}`" if flag else ""


def _example_table() -> str:
    """The table `collide2d init` writes, as it writes it."""
    from collide2d.runner.command import newproject

    return newproject.TABLE_TEXT.strip()


# ---------------------------------------------------------------------------------------------
# Exit statuses, from their module


def exit_statuses_page() -> str:
    from collide2d.runner.command import exitcodes

    path = Path(exitcodes.__file__)
    source = path.read_text(encoding="utf-8")
    comments = {}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            comments[tok.start[0]] = tok.string.lstrip("# ").strip()
    out = [
        GENERATED.format(source="runner/command/exitcodes.py"),
        "# Exit statuses",
        "",
        "Every `collide2d` command exits with one of these (one copy for all commands,"
        " `collide2d.runner.command.exitcodes`). `check` and `bless` exit with the worst status"
        " of their scenarios (3 over 2 over 1). A command killed by a fatal signal keeps the"
        " shell's status (139 for SIGSEGV) after one line naming the signal"
        " ([The kernel cache](../explanation/kernels.md#the-kernel-cache)).",
        "",
        "| status | name | meaning |",
        "| --- | --- | --- |",
    ]
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
            (target,) = node.targets
            meaning = comments.get(node.lineno, "")
            out.append(f"| {node.value.value} | `{target.id}` | {cell(meaning)} |")
    out.append("")
    return "\n".join(out)
