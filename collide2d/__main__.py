"""`python -m collide2d` is the `collide2d` command."""

import sys

from collide2d.runner.command.main import main

sys.exit(main())
