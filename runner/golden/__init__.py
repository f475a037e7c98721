"""Golden regression (docs/goldens.md): keep a scenario's events, final state and frames honest.

The harness has four roles, one module each: `serialize` (a run's results as the files of a golden
folder), `store` (read a golden folder whole, swap one in whole), `compare` (pure rules: events,
final state, frames) and `report` (console text, images, JSON; `page`, the HTML page). `session`
joins them for one scenario (`check_run`, `bless_run`); `cli` (the `check` and `bless` commands) and
`plugin` (pytest) drive it. This module only re-exports what its users import.

It may import what the command line may (`collide2d.engine`, `runner.lanes`, `runner.compiling`,
`runner.scenario`, `runner.output`, `runner.run`), the command line's shared parts
(`runner.command`: options, settings, exit statuses) and `runner.sweep` (`check` on a cluster); the
command line loads it by name, pytest through `plugin`.
"""

from collide2d.runner.golden.session import (
    CREATED,
    UNCHANGED,
    UPDATED,
    Blessed,
    bless_command,
    bless_run,
    check_run,
    frame_pixel_bound,
    golden_files,
    golden_frames,
)
from collide2d.runner.golden.store import shown_path

__all__ = [
    "CREATED",
    "UNCHANGED",
    "UPDATED",
    "Blessed",
    "bless_command",
    "bless_run",
    "check_run",
    "frame_pixel_bound",
    "golden_files",
    "golden_frames",
    "shown_path",
]
