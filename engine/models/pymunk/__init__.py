"""The pymunk model: a scenario run in pymunk (https://www.pymunk.org), the `bench` extra's peer.

`Model` meets the model protocol (`collide2d.engine.models.protocol`) by driving a pymunk space:
one `space.step(1 / fps)` per tick, no rotation (every body has an infinite moment), elasticity
and friction from the scenario (each object's `restitution` and `friction`, the walls' from the
world; pymunk combines the two sides of a contact by multiplying them), gravity from the world.
It is registered under the name `pymunk` through collide2d's own entry point (group
`collide2d.models`), so `model: pymunk` runs a scenario in pymunk and its goldens, report, viewer
and error against the exact model come as for any model; `collide2d bench`'s peer timing steps
the same `Model` (`runner.bench.peers`).
"""

from collide2d.engine.models.pymunk.model import Model

__all__ = ["Model"]
