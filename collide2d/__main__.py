"""`python -m collide2d` is the `collide2d` command."""

import sys

from collide2d.runner.cli import main

sys.exit(main())
