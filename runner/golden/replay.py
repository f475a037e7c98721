"""A failing check's viewer: the scenario run again with the viewer's recorder, the golden's
frames as its ghost.

`check_run` keeps the run's results but not every tick's state, which a viewer needs; a failure
with a report folder runs the scenario once more (the same bytes: a run is deterministic) with a
`runner.output.viewerdata.Recorder` and the overlays its scenario asks for, and hands the
golden's frames to the recorder as the ghost. A run too long to view (`viewerdata.MAX_POSITIONS`)
gets no viewer.
"""

from __future__ import annotations

from collide2d.runner import lanes
from collide2d.runner.output import viewerdata
from collide2d.runner.output.overlay import Overlay
from collide2d.runner.scenario.load import ScenarioError


def viewer_page(scenario, golden_frames: dict) -> bytes | None:
    """viewer.html bytes of `scenario`'s run with `golden_frames` (frame -> RGB) as the ghost,
    or None when the run is too long to view."""
    from collide2d.runner.run import drive  # the runner loads only when a viewer is asked for

    layer = Overlay(scenario, scenario.output.overlay, record=True)
    try:
        recorder = viewerdata.Recorder(scenario, layer)
    except ScenarioError:
        return None
    with lanes.run(scenario, 0):
        drive(
            scenario,
            log_events=True,
            on_events=recorder.events,
            on_tick=recorder.add,
            overlay=layer,
        )
    recorder.set_ghost(golden_frames)
    return recorder.page()
