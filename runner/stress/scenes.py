"""The stress scenes: hostile worlds built in code, each with its length and what to expect.

`scenes(quick)` lists them, quick (shorter, smaller, for CI) or full: a million-tick run, objects
crossing the world in one tick, mass ratios to 1e24, 1x1 boxes beside a 2000x2000 one, dense
packing with a Newton's cradle, a world 1e6 px wide, positions at half pixels, a room of static
walls, and a runaway that must stop with a clear error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from collide2d.engine.models import MODEL_NAMES
from collide2d.engine.world import Bodies, WorldSpec


@dataclass(frozen=True)
class Scene:
    """One hostile scene: the world, the objects and how long to run, and what to expect.

    models: the models it applies to (the paper model needs whole-pixel positions).
    expect_stop: models that must stop it with a clear error (a runaway), not run it through.
    room: (x0, y0, x1, y1) px that movers must stay inside (checked under `exact`), or None.
    """

    name: str
    about: str
    world: WorldSpec
    bodies: Bodies
    ticks: int
    models: tuple[str, ...] = MODEL_NAMES
    expect_stop: tuple[str, ...] = ()
    room: tuple[float, float, float, float] | None = None


def _grid(nx: int, ny: int, x0: float, y0: float, step_x: float, step_y: float) -> np.ndarray:
    """(nx * ny, 2) corners of an nx x ny grid, row by row, px."""
    gx, gy = np.meshgrid(np.arange(nx), np.arange(ny))
    return np.stack([x0 + step_x * gx.ravel(), y0 + step_y * gy.ravel()], axis=1).astype(float)


def _long_run(quick: bool) -> Scene:
    pos = _grid(6, 4, 20, 20, 50, 50)
    n = pos.shape[0]
    k = np.arange(n)
    vel = np.stack([(10 + 10 * (k % 3)) * (-1.0) ** k, (10 + 10 * (k % 2)) * (-1.0) ** (k // 2)], 1)
    return Scene(
        "long_run",
        "24 boxes bouncing in a 320x240 world for 10^6 ticks",
        WorldSpec(320, 240, 10),
        Bodies.boxes(pos, 10, vel, mass=1.0 + k % 4),
        20_000 if quick else 1_000_000,
    )


def _cross_in_one_tick(quick: bool) -> Scene:
    pos = [[5, 10], [100, 50], [50, 100], [150, 80], [170, 10]]
    size = [[10, 10], [10, 10], [1, 1], [20, 20], [5, 5]]
    vel = [[5000, 0], [0, -3000], [2170, 1330], [-70, 40], [-4990, 2510]]
    return Scene(
        "cross_in_one_tick",
        "objects crossing the whole 200x120 world several times in one tick",
        WorldSpec(200, 120, 10),
        Bodies(**_box_fields(pos, size, vel, mass=[1, 2, 0.5, 10, 1])),
        2_000 if quick else 20_000,
    )


def _mass_ratios(quick: bool) -> Scene:
    # Lane k (a 1-D strip, no vertical motion) holds a box of mass 10^k near the middle, nearly at
    # rest, and a box of mass 10^-k on each side bouncing between it and a wall: mass ratios up to
    # 1e24. (A heavy box that drives a light one into a wall would need about pi * sqrt(M / m)
    # collisions, 10^12 here, and stop the exact model at its event cap: the physics, not a bug.)
    k = np.repeat(np.arange(13), 3)
    slot = np.tile(np.arange(3), 13)
    pos = np.stack([np.choose(slot, [40.0, 195.0, 330.0]), 5.0 + 15.0 * k], 1)
    vel = np.stack([np.choose(slot, [100.0, 0.0, -150.0]), np.zeros(k.shape[0])], 1)
    vel[(slot == 1) & (k == 12)] = [0.25, 0.0]
    mass = 10.0 ** np.where(slot == 1, k, -k)
    return Scene(
        "mass_ratios",
        "masses 1e-12 ... 1e12 side by side: light boxes bouncing off heavy ones (ratios to 1e24)",
        WorldSpec(400, 200, 100),
        Bodies.boxes(pos, 10, vel, mass=mass),
        3_000 if quick else 20_000,
    )


def _tiny_beside_huge(quick: bool) -> Scene:
    tiny = np.concatenate(
        [_grid(8, 8, 20, 20, 50, 50), _grid(8, 8, 2620, 2620, 45, 45), [[499, 600], [700, 2500]]]
    )
    n = tiny.shape[0]
    k = np.arange(n)
    pos = np.concatenate([[[500.0, 500.0]], tiny])
    size = np.concatenate([[[2000.0, 2000.0]], np.ones((n, 2))])
    vel = np.concatenate(
        [[[1.0, -1.0]], np.stack([37.0 * (-1.0) ** k, 23.0 * (-1.0) ** (k // 2)], 1)]
    )
    vel[-2] = [200.0, 0.0]  # touching the huge box's left side, moving into it
    vel[-1] = [0.0, -300.0]  # just under it, moving up into it
    mass = np.concatenate([[1e6], np.full(n, 1e-3)])
    return Scene(
        "tiny_beside_huge",
        "1x1 boxes beside a 2000x2000 box, some touching it",
        WorldSpec(3000, 3000, 10),
        Bodies(**_box_fields(pos, size, vel, mass=mass)),
        2_000 if quick else 20_000,
    )


def _dense_packing(quick: bool) -> Scene:
    side = 10 if quick else 15
    block = _grid(side, side, 25, 25, 10, 10)
    cradle = _grid(5, 1, 50, 5, 10, 10)
    pos = np.concatenate([block, cradle])
    rng = np.random.default_rng(0)
    vel = rng.choice([-10.0, 0.0, 10.0], size=(pos.shape[0], 2))
    vel[-5:] = 0.0
    vel[-5] = [20.0, 0.0]  # Newton's cradle: the first of five touching boxes hits the row
    return Scene(
        "dense_packing",
        f"{side}x{side} touching boxes with random velocities and a Newton's cradle",
        WorldSpec(200, 200, 10),
        Bodies.boxes(pos, 10, vel),
        1_000 if quick else 5_000,
    )


def _far_from_origin(quick: bool) -> Scene:
    n = 10
    k = np.arange(n)
    pos = np.concatenate([np.stack([999_000.0 + 90 * k, 20.0 + 15 * k], 1), [[3.0, 50.0]]])
    vel = np.concatenate(
        [np.stack([123.456 * (-1.0) ** k, 7.25 * (-1.0) ** (k // 2)], 1), [[1e7, 3.5]]]
    )
    return Scene(
        "far_from_origin",
        "a 1e6 px wide world: boxes near x = 1e6 and one crossing it every tick",
        WorldSpec(1_000_000, 200, 10),
        Bodies.boxes(pos, 10, vel),
        2_000 if quick else 20_000,
    )


def _half_pixel(quick: bool) -> Scene:
    def below(x):
        return float(np.nextafter(x, -np.inf))

    def above(x):
        return float(np.nextafter(x, np.inf))

    pos = [
        [10.5, 10.5],
        [below(30.5), above(10.5)],
        [50.5, 40.0],
        [70.0, 60.5],
        [below(10.5), above(80.5)],
        [below(1.5), below(50.5)],
        [below(0.5), 90.0],
    ]
    vel = [[4.0, 4.0], [-4.0, 12.0], [2.0, 0.0], [0.0, -6.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    static = [False, False, False, False, False, True, False]
    return Scene(
        "half_pixel",
        "positions at and next to .5 px, moving by half pixels (rounding to pixels)",
        WorldSpec(100, 100, 8),
        Bodies.boxes(pos, 5, vel, static=static),
        2_000 if quick else 20_000,
        models=("stepped", "exact"),
    )


def _static_walls(quick: bool) -> Scene:
    ring = np.concatenate(
        [
            _grid(20, 1, 20, 20, 10, 10),  # top
            _grid(20, 1, 20, 210, 10, 10),  # bottom
            _grid(1, 18, 20, 30, 10, 10),  # left
            _grid(1, 18, 210, 30, 10, 10),  # right
        ]
    )
    movers = _grid(4, 4, 50, 50, 40, 40)
    k = np.arange(movers.shape[0])
    vel = np.stack(
        [(200.0 - 40 * (k % 4)) * (-1.0) ** k, (60.0 + 20 * (k % 5)) * (-1.0) ** (k // 4)], 1
    )
    pos = np.concatenate([ring, movers])
    size = np.concatenate([np.full((ring.shape[0], 2), 10.0), np.full((movers.shape[0], 2), 6.0)])
    static = np.concatenate([np.ones(ring.shape[0], bool), np.zeros(movers.shape[0], bool)])
    allvel = np.concatenate([np.zeros((ring.shape[0], 2)), vel])
    return Scene(
        "static_walls",
        "a room walled by 76 static boxes, 16 fast movers inside",
        WorldSpec(240, 240, 20),
        Bodies(**_box_fields(pos, size, allvel, static=static)),
        3_000 if quick else 20_000,
        room=(30.0, 30.0, 210.0, 210.0),
    )


def _runaway(quick: bool) -> Scene:
    return Scene(
        "runaway",
        "one box at 1e9 px/s in a 40x40 world: a clear stop, never a hang",
        WorldSpec(40, 40, 1),
        Bodies.boxes([[15.0, 15.0]], 10, [[1e9, 0.0]]),
        3,
        expect_stop=("stepped", "exact"),
    )


def _box_fields(pos, size, vel, *, mass=None, static=None) -> dict:
    """Bodies fields of boxes with per-object sizes (Bodies.boxes broadcasts one size)."""
    b = Bodies.boxes(pos, 1.0, vel, mass=mass, static=static)
    fields = {f: getattr(b, f) for f in b.__dataclass_fields__}
    fields["size"] = np.asarray(size, np.float64).reshape(-1, 2).copy()
    return fields


SCENES = (
    _long_run,
    _cross_in_one_tick,
    _mass_ratios,
    _tiny_beside_huge,
    _dense_packing,
    _far_from_origin,
    _half_pixel,
    _static_walls,
    _runaway,
)


def scenes(quick: bool = False) -> list[Scene]:
    """Every stress scene, quick (shorter, smaller) or full."""
    return [build(quick) for build in SCENES]
