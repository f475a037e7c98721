"""`python -m collide2d.runner` is the `collide2d` command too."""

import sys

from collide2d.runner.command.main import main

sys.exit(main())
