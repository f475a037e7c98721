"""collide2d's runner: everything a user touches — scenarios, runs, outputs, goldens, the CLI."""
