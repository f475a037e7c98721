"""The `exact` model: event-driven elastic collisions, the reference for every result.

This package holds what only the exact model uses: `model` (the `Model` class and its main
loop), `apply` (the events it applies), `state` (the columns of its arrays, its scalar state, its
statuses), `heap` (the event queue: a 4-ary heap of predicted contacts), `horizonqueue` (each
moving object's next wall contact or cell crossing, in a calendar queue), `cells` (the grid's
per-cell lists of moving objects), `prediction` (an object's next events), `arccontact` (the
contact of a falling body and a standing one, on their curved relative path) and `jam` (the
objects a jam holds, named when it stops the model). `collide2d.engine.models.make("exact", ...)`
builds it from `Model`, which this package re-exports.

Its modules may import numpy, each other and the shared stages of `collide2d.engine` (jit,
contact, events, response, shapes, broadphase, sort, noroom, errors, world, and the constants of
`collide2d.engine.models`); never another model's package nor `collide2d.runner`. Nothing
outside this package imports its modules but the tests (the scenario reader checks no room to
move through engine/noroom.py).
"""

from collide2d.engine.models.exact.model import Model

__all__ = ["Model"]
