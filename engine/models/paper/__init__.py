"""The `paper` model: the paper's rules, reproduced exactly in integers.

This package holds what only the paper model uses: `model` (the `Model` class and its tick kernel,
`_run`, over integer state) and `records` (the kernel's state records, read by field). Its step
rates (`engine/motion.py`) stay with the shared modules, since the scenario reader checks velocities
by them too. `collide2d.engine.models.make("paper", ...)` builds it from `Model`, which this package
re-exports.

Its modules may import numpy, each other and the shared stages of `collide2d.engine` (jit,
motion, broadphase, sort, threads, splitchoice, events, errors, world); never another model's
package nor `collide2d.runner`. Nothing outside this package imports its modules but the tests.
"""

from collide2d.engine.models.paper.model import Model

__all__ = ["Model"]
