"""The command line and the project's settings: parsing and dispatch, the shared options,
`[tool.collide2d]`, `init`, `config`, `validate`, the exit statuses and progress bars.

It may import everything else of the runner; nothing under `scenario` or `output` imports it,
except for the exit statuses and the progress bar, which are leaves."""
