"""Registers the golden regression plugin: `--update-goldens`, `--golden-report`, `golden_check`."""

pytest_plugins = ["runner.golden.plugin"]
