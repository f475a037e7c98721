"""`python -m runner` is the `collide2d` command."""

import sys

from runner.cli import main

sys.exit(main())
