"""A loaded scenario drawn again for another seed: what a sweep's seed changes, and nothing more.

A sweep's seed goes to every `generate` block of the file (`runner.sweep.matrix`), and the only part
of a loaded scenario that a block's seed changes is what `runner.scenario.generate` draws from it:
the positions and velocities of the block's objects, the last rows of `bodies` (`Scenario.generated`
keeps each block's spec). So `reseed(scenario, seed)` draws the blocks again around the same listed
objects, exactly as the loader does (`runner.scenario.assemble.bodies`), and refuses what the loader
would refuse for that seed: boxes that cannot all be placed (`PlacementError`) and, under the
`exact` model, a moving object left with no room on an axis it moves on (`engine.noroom.no_room`).
The result is the scenario the loader gives for the file with that seed (a test holds the two
equal), at the cost of the drawing alone: no file read, no YAML, no checks that the seed cannot
change. `Reseeded` is raised with the loader's reason when refused; the sweep then loads that run in
full for the located message.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from collide2d.engine.noroom import no_room, no_room_message
from collide2d.runner import lanes
from collide2d.runner.scenario import generate


class Reseeded(Exception):
    """The scenario refused for this seed; str is the reason (the loader's, unlocated)."""


def reseed(scenario, seed: int):
    """`scenario` with every generate block drawn from `seed` (see the module docstring)."""
    if not scenario.generated:
        return scenario
    specs = [dataclasses.replace(b, seed=seed) for b in scenario.generated]
    bodies = scenario.bodies
    fixed = bodies.n - sum(int(s.count) for s in specs)
    pos, size = bodies.pos[:fixed], bodies.size[:fixed]
    world = scenario.world
    try:
        drawn = generate.generate(world.width, world.height, pos, size, specs)
    except generate.PlacementError as exc:
        raise Reseeded(f"generate[{exc.block}]: {exc}") from None
    bodies = dataclasses.replace(
        bodies,
        pos=np.concatenate([pos] + [d[0] for d in drawn]).reshape(bodies.n, 2),
        vel=np.concatenate([bodies.vel[:fixed]] + [d[1] for d in drawn]).reshape(bodies.n, 2),
    )
    if scenario.model == "exact":
        with lanes.objects(bodies.n):
            found = no_room(world, bodies, scenario.geometry)
        if found:
            raise Reseeded(no_room_message(found, bodies, scenario.names))
    return dataclasses.replace(scenario, bodies=bodies)
