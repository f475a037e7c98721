"""The `stepped` model: fixed-step elastic collisions with float state.

This package holds what only the stepped model uses: `model` (the `Model` class and its state),
`step` (the step kernel, its stages in the order of STAGES, and the run loop), and one module
per stage: `move` (move and walls), `candidates` (the candidate list and the order the objects
are kept in), `narrow` (the listed pairs in contact, in order) and `pairs` (the exchange and the
push), with `approach` (a pair's contact after a step: its normal from the direction of
approach). A world with gravity, restitution or friction takes the settling path instead:
`settle` (its step and run loop), `fall` (exact motion under gravity, wall bounces), `land` (a
body the move took far into a static object, put back where it met it), `touch` (contacts,
wake), `solver` (velocities and overlap, never adding energy), `sleep` and `sunk` (a body asleep
inside a static object stops the run).
`collide2d.engine.models.make("stepped", ...)` builds it from `Model`, which this package
re-exports.

Its modules may import numpy, each other and the shared stages of `collide2d.engine` (jit,
contact, response, shapes, broadphase, sort, threads, splitchoice, events, errors, world);
never another model's package nor `collide2d.runner`. Nothing outside this package imports its
modules but the tests and the benchmarks.
"""

from collide2d.engine.models.stepped.model import Model

__all__ = ["Model"]
