"""collide2d's runner: everything a user touches — scenarios, runs, outputs, goldens, the CLI.

One package or module per concern, each importing only those listed before it (and the engine):
- `lanes` (whether a run's kernels are compiled or interpreted, weighing what `compilecost` says
  compiling them would take) and `compiling` (compile time kept apart, the first-run notice),
  beside the engine;
- `scenario`: reading and checking a scenario file;
- `output`: what the runner writes and shows, and where;
- `interrupt`: Ctrl-C answered within a second, whatever runs (the command's watchdog);
- `run`: a model driven over a scenario's ticks, its frames and events handed to the writers;
- `command`: the command line and the project's settings;
- `stress`, `bench`, `sweep` and `golden`: the commands with a package of their own (a sweep reports
  the position error as `bench` measures it, and `check` runs on a cluster through `sweep`);
- `prebuild`: the kernels a wheel ships, compiled by running scenes through `command` (a release
  step, not a command of `collide2d`).
Each package's docstring says what it may import.
"""
