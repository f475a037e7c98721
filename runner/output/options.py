"""What a run writes besides `final.csv` and `summary.json` (always written): `RunOptions`, as
`collide2d run`'s options or `collide2d.run`'s arguments ask, else as the scenario's `output` says
(`RunOptions.asked`).
"""

from __future__ import annotations

from dataclasses import dataclass

from collide2d.runner.scenario.load import Scenario


@dataclass(frozen=True)
class RunOptions:
    """What `collide2d run` writes: PNG frames, GIF, events (final.csv and summary always)."""

    png: bool
    gif: bool
    events: bool
    scale: int = 1
    quiet: bool = False
    viewer: bool = False  # viewer.html beside the GIF (runner.output.viewerdata)
    overlay: tuple = ()  # overlays drawn into the PNG and GIF frames (runner.output.overlay)

    @classmethod
    def asked(
        cls, scenario: Scenario, *, events, png, gif, viewer, overlay, scale, quiet
    ) -> RunOptions:
        """What a run was asked to write (`collide2d run`'s options, `collide2d.run`'s arguments),
        else, where None, what the scenario's `output` says."""
        said = scenario.output
        return cls(
            png=bool(said.frames) if png is None else png,
            gif=said.gif if gif is None else gif,
            events=events,
            scale=scale,
            quiet=quiet,
            viewer=said.viewer if viewer is None else viewer,
            overlay=said.overlay if overlay is None else tuple(overlay),
        )
