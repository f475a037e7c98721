"""The stress scenes under gravity, restitution and friction (the stepped model's settling path,
docs/models.md#stepped-gravity-restitution-and-friction): huge gravity, e = 0 and e = 1, huge
friction, a 20-box stack standing for 10 s, and boxes dropped at the speed limit onto a pile. Each
must stay finite and inside the world, and its total energy (kinetic and potential) must never rise
above where it began (checks.py). `every_scene` lists them after the scenes of scenes.py: the
suite's list."""

from __future__ import annotations

import numpy as np

from collide2d.engine.world import Bodies, WorldSpec
from collide2d.runner.stress.scenes import Scene, scenes

G = 980.0


def _with(bodies: Bodies, e: float, mu: float) -> Bodies:
    """The bodies with restitution e and friction mu each."""
    n = bodies.n
    return Bodies(**{**bodies.__dict__, "restitution": np.full(n, e), "friction": np.full(n, mu)})


def _scatter(n: int, seed: int, width: float, height: float, size: float, speed: float):
    """n boxes on a jittered grid over the upper half of the world, at random speeds."""
    rng = np.random.default_rng(seed)
    cols = max(1, int(width // (size * 1.5)))
    k = np.arange(n)
    pos = np.stack([k % cols, k // cols], axis=1) * size * 1.5 + rng.uniform(0, size * 0.4, (n, 2))
    pos[:, 1] = np.minimum(pos[:, 1], height / 2)
    vel = rng.uniform(-speed, speed, (n, 2))
    return Bodies.boxes(pos, size, vel, mass=rng.uniform(0.5, 2.0, n))


def _huge_gravity(quick: bool) -> Scene:
    return Scene(
        "huge_gravity",
        "30 boxes under 10^6 px/s^2, e 0.5, mu 0.5",
        WorldSpec(320, 240, 60, gravity=(0.0, 1e6)),
        _with(_scatter(30, 1, 320, 240, 10, 100), 0.5, 0.5),
        120 if quick else 1200,
        models=("stepped",),
    )


def _pile(e: float, quick: bool) -> Scene:
    return Scene(
        f"pile_e{e:g}",
        f"60 boxes dropped in a box, e {e:g}, mu 0.3",
        WorldSpec(200, 200, 60, gravity=(0.0, G)),
        _with(_scatter(60, 2, 200, 200, 8, 60), e, 0.3),
        300 if quick else 1200,
        models=("stepped",),
    )


def _huge_friction(quick: bool) -> Scene:
    return Scene(
        "huge_friction",
        "40 boxes flung sideways with mu 1000 (and walls mu 1000)",
        WorldSpec(320, 200, 60, gravity=(0.0, G), friction=1000.0),
        _with(_scatter(40, 3, 320, 200, 10, 400), 0.3, 1000.0),
        240 if quick else 1200,
        models=("stepped",),
    )


def _tall_stack(quick: bool) -> Scene:
    pos = [[90.0, 390.0 - 10.0 * k] for k in range(20)]
    return Scene(
        "tall_stack",
        "a 20-box stack standing on the floor for 10 s",
        WorldSpec(200, 400, 60, gravity=(0.0, G)),
        _with(Bodies.boxes(pos, [20, 10], [[0, 0]]), 0.3, 0.5),
        600,
        models=("stepped",),
    )


def _speed_limit_drop(quick: bool) -> Scene:
    # a pile resting on the floor, and boxes above it moving down at just under a box per step
    pile = [[10.0 * i + 5.0, 190.0 - 10.0 * j] for j in range(4) for i in range(18)]
    drops = [[20.0 * i + 10.0, 20.0] for i in range(9)]
    vel = [[0.0, 0.0]] * len(pile) + [[0.0, 0.95 * 10 * 60]] * len(drops)
    return Scene(
        "speed_limit_drop",
        "boxes at just under a box per step dropped onto a pile",
        WorldSpec(200, 200, 60, gravity=(0.0, G)),
        _with(Bodies.boxes(pile + drops, 10, vel), 0.5, 0.5),
        240 if quick else 1200,
        models=("stepped",),
    )


def falling_scenes(quick: bool) -> list[Scene]:
    """The scenes of this module, quick (shorter) or full."""
    return [
        _huge_gravity(quick),
        _pile(0.0, quick),
        _pile(1.0, quick),
        _huge_friction(quick),
        _tall_stack(quick),
        _speed_limit_drop(quick),
    ]


def every_scene(quick: bool) -> list[Scene]:
    """The stress scenes of scenes.py and of this module, quick (shorter) or full."""
    return scenes(quick) + falling_scenes(quick)
