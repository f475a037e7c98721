"""Command-line options shared by the commands that read scenarios (run, validate, check, bless).

`add_limit_arguments` / `limits_from_args` carry the bounds of docs/limits.md (`--max-objects`,
`--max-ticks`, `--max-side`, `--max-frames`, `--max-file-bytes`, `--max-yaml-nodes`, and
`--max-output-bytes` and `--max-frame-bytes` where frames are written);
`add_override_arguments` / `overrides_from_args` carry `--model`, `--fps`, `--ticks`, which override
the scenario file (the loader checks the result again); `add_cap_argument` adds
`--max-events-per-tick` (run, check, bless), the exact model's bound, which overrides the scenario's
`model.max_events_per_tick` and goes to the loader with the overrides.
"""

from __future__ import annotations

import argparse
import difflib

from collide2d.engine.models import MAX_EVENTS_PER_TICK, MODEL_NAMES, names, names_for
from collide2d.runner.scenario.limits import Limits

_LIMIT_OPTIONS = (
    ("--max-objects", "max_objects", "objects in a scenario"),
    ("--max-ticks", "max_ticks", "ticks of a run"),
    ("--max-side", "max_side", "pixels per world side"),
    ("--max-frames", "max_frames", "frames a `frames` entry may ask for, or a run write"),
    ("--max-file-bytes", "max_file_bytes", "bytes in a scenario file"),
    ("--max-yaml-nodes", "max_yaml_nodes", "YAML values in a scenario file"),
)
_OUTPUT_OPTIONS = (
    ("--max-output-bytes", "max_output_bytes", "bytes of frame files and event log on disk"),
    ("--max-frame-bytes", "max_frame_bytes", "bytes of one frame in memory (RGB, scaled)"),
)


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1."""
    value = whole(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be at least 1")
    return value


def whole(text: str) -> int:
    """argparse type: a whole number (any sign; the loader judges the range)."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None


def add_limit_arguments(parser: argparse.ArgumentParser, *, output: bool = False):
    """Add the limit options (defaults from Limits) in a group of their own, returned; `output`
    adds --max-output-bytes too."""
    defaults = Limits()
    group = parser.add_argument_group("limits")
    for flag, field, what in _LIMIT_OPTIONS + (_OUTPUT_OPTIONS if output else ()):
        group.add_argument(
            flag,
            dest=field,
            type=positive_int,
            default=None,
            metavar="N",
            help=f"largest number of {what} (default {getattr(defaults, field):,}, or the "
            "project's [tool.collide2d.limits])",
        )
    return group


def limits_from_args(args: argparse.Namespace, project=None) -> Limits:
    """The Limits asked for on the command line, over the project's `[tool.collide2d.limits]`
    (a runner.command.settings.Config) when given, over the defaults."""
    fields = [f for _, f, _ in _LIMIT_OPTIONS + _OUTPUT_OPTIONS]
    given = {f: getattr(args, f) for f in fields if getattr(args, f, None)}
    return project.limits(given) if project is not None else Limits(**given)


def add_override_arguments(parser: argparse.ArgumentParser) -> None:
    """Add --model, --fps and --ticks, which override the scenario file."""
    parser.add_argument(
        "--model",
        type=model_name,
        metavar="MODEL",
        help=f"model to use instead of the file's: {', '.join(MODEL_NAMES)} or a plugin's",
    )
    parser.add_argument("--fps", type=whole, metavar="F", help="ticks per second instead")
    parser.add_argument("--ticks", type=whole, metavar="N", help="ticks to run instead")


def model_name(text: str) -> str:
    """`--model M`: a built-in model or a registered plugin (engine.models; the plugins are looked
    up only for a name that is not built in)."""
    if text not in names_for(text):
        near = difflib.get_close_matches(text, names_for(text), n=1)
        hint = f"did you mean '{near[0]}'?" if near else "expected " + " | ".join(names())
        raise argparse.ArgumentTypeError(f"unknown model {text!r}; {hint}")
    return text


def add_cap_argument(parser: argparse.ArgumentParser) -> None:
    """Add --max-events-per-tick (the exact model's cap; over the scenario's model option)."""
    parser.add_argument(
        "--max-events-per-tick",
        dest="max_events_per_tick",
        type=positive_int,
        metavar="N",
        help="largest number of wall and pair events in one tick of the exact model, a runaway "
        "past it (default: the scenario's model.max_events_per_tick, else "
        f"{MAX_EVENTS_PER_TICK:,})",
    )


def overrides_from_args(args: argparse.Namespace) -> dict:
    """{"model", "fps", "ticks", "max_events_per_tick"} from the command line; None where not
    given."""
    return {
        key: getattr(args, key, None) for key in ("model", "fps", "ticks", "max_events_per_tick")
    }


def add_threads_argument(p: argparse.ArgumentParser) -> None:
    """`--threads N`: threads the kernels may use (default: every core; engine.threads)."""
    p.add_argument(
        "--threads",
        type=positive_int,
        default=None,
        metavar="N",
        help="threads for the stages that split large scenes (default: all cores); the "
        "results are the same bytes for any N",
    )


def add_jit_argument(p: argparse.ArgumentParser) -> None:
    """`--jit MODE`: compiled or interpreted kernels (runner.lanes)."""
    p.add_argument(
        "--jit",
        choices=("auto", "on", "off"),
        default=None,
        help="compile the kernels with numba: auto (default: each run starts interpreted and "
        "compiles once the ticks left would take longer than compiling the kernels it calls), "
        "on (every run), off (never: plain Python, slow for big scenes); the results are the "
        "same bytes",
    )


def apply_jit(args: argparse.Namespace, project=None) -> None:
    """Put the command line's `--jit`, else the project's `[tool.collide2d] jit`, else the
    environment's COLLIDE2D_JIT (else auto) in force (runner.lanes)."""
    from collide2d.runner import lanes

    given = getattr(args, "jit", None)
    if given is None and project is not None:
        given = project.value("jit")
    lanes.set_mode(given)


def apply_threads(args: argparse.Namespace, project=None) -> None:
    """Put the command line's `--threads`, else the project's `[tool.collide2d] threads` (a
    runner.command.settings.Config), else all cores, in force for the compiled kernels (from when
    numba loads: engine.threads.request)."""
    from collide2d.engine.threads import request

    given = getattr(args, "threads", None)
    if given is None and project is not None:
        given = project.value("threads")
    request(given)
