"""What a run writes and where: the files, the run folder and its swap, overlays, the viewer
and the output budget.

It may import `collide2d.engine` (drawing) and `collide2d.runner.scenario.load` (the settings a
scenario gives its outputs); the command line and the run import it, never the other way."""
