"""The exit statuses of every `collide2d` command (docs/command-line.md#exit-statuses), one copy for
all of them."""

EXIT_OK = 0  # fine
EXIT_DIFFERENCE = 1  # a check found a difference (goldens), or stress found a broken invariant
EXIT_BAD_INPUT = 2  # bad input or usage: a refused scenario, a refused folder, a runaway
EXIT_UNEXPECTED = 3  # an unexpected error: a bug, reported in one line (the traceback with --debug)
EXIT_INTERRUPTED = 130  # stopped by Ctrl-C (128 + SIGINT), as shells report it
