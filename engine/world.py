"""The world's state as parallel arrays: what every model, the rasteriser and the writers share.

`WorldSpec` is the fixed frame (size in pixels, ticks per second). `Bodies` is the per-object table
in id order: the hot arrays the models read (`kind`, `pos`, `size`, `vel`, `mass`, `static`, and
the polygon vertices, which give exact shapes their outline), and apart from them, in
`Bodies.looks`, the drawing data only the rasteriser reads (`Looks`: colour and fill). Names and
YAML lines are cold data and live with the scenario, not here. A box's position is its top-left
corner; its box covers `[x, x+w) x [y, y+h)`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KIND_BOX = 0
KIND_CIRCLE = 1
KIND_POLYGON = 2
KIND_NAMES = ("box", "circle", "polygon")


@dataclass(frozen=True)
class WorldSpec:
    """The world rectangle in pixels (x right, y down), the ticks per simulated second, and the
    physics of docs/scenario-format.md#gravity-restitution-and-friction: gravity (px/s², y down),
    the walls' restitution and friction. The defaults (no gravity, elastic frictionless walls) are
    the elastic world.
    """

    width: int
    height: int
    fps: int
    gravity: tuple[float, float] = (0.0, 0.0)
    restitution: float = 1.0
    friction: float = 0.0

    @property
    def has_gravity(self) -> bool:
        return self.gravity[0] != 0.0 or self.gravity[1] != 0.0


@dataclass(frozen=True)
class Looks:
    """How objects are drawn, apart from the arrays the models read; n objects.

    color      (n,)   uint8    index into the scenario's palette (0 is the background)
    fill       (n,)   bool     paint the inside as well as the outline
    """

    color: np.ndarray
    fill: np.ndarray


@dataclass(frozen=True)
class Bodies:
    """Per-object arrays in id order; n objects, m polygon vertices in all.

    kind       (n,)   int8     KIND_BOX / KIND_CIRCLE / KIND_POLYGON
    pos        (n, 2) float64  top-left corner of the box, px
    size       (n, 2) float64  box width and height, px
    vel        (n, 2) float64  px per second
    mass       (n,)   float64  inf for static objects
    static     (n,)   bool     static objects never move
    vert_start (n+1,) int64    polygon i's vertices are verts[vert_start[i]:vert_start[i+1]]
    verts      (m, 2) int64    polygon vertices relative to the box's top-left corner
    looks      Looks           colour and fill, for drawing only
    restitution (n,)  float64  e in [0, 1] (default 1: elastic)
    friction   (n,)   float64  Coulomb's mu >= 0 (default 0: frictionless)
    """

    kind: np.ndarray
    pos: np.ndarray
    size: np.ndarray
    vel: np.ndarray
    mass: np.ndarray
    static: np.ndarray
    vert_start: np.ndarray
    verts: np.ndarray
    looks: Looks
    restitution: np.ndarray | None = None
    friction: np.ndarray | None = None

    def __post_init__(self):
        n = self.kind.shape[0]
        if self.restitution is None:
            object.__setattr__(self, "restitution", np.ones(n))
        if self.friction is None:
            object.__setattr__(self, "friction", np.zeros(n))

    @property
    def n(self) -> int:
        return int(self.kind.shape[0])

    @property
    def inv_mass(self) -> np.ndarray:
        """(n,) float64: 1/mass, 0 for static objects."""
        inv = np.zeros(self.n)
        movable = ~self.static
        inv[movable] = 1.0 / self.mass[movable]
        return inv

    @staticmethod
    def boxes(pos, size, vel, *, mass=None, static=None, color=None, fill=None) -> Bodies:
        """Bodies made only of boxes, for tests and generated scenes."""
        pos = np.asarray(pos, dtype=np.float64).reshape(-1, 2)
        n = pos.shape[0]
        size = np.broadcast_to(np.asarray(size, dtype=np.float64), (n, 2)).copy()
        vel = np.broadcast_to(np.asarray(vel, dtype=np.float64), (n, 2)).copy()
        static = np.zeros(n, bool) if static is None else np.asarray(static, bool).copy()
        mass = np.ones(n) if mass is None else np.asarray(mass, np.float64).copy()
        mass = np.where(static, np.inf, mass)
        vel[static] = 0.0
        return Bodies(
            kind=np.full(n, KIND_BOX, np.int8),
            pos=pos.copy(),
            size=size,
            vel=vel,
            mass=mass,
            static=static,
            vert_start=np.zeros(n + 1, np.int64),
            verts=np.zeros((0, 2), np.int64),
            looks=Looks(
                color=np.ones(n, np.uint8) if color is None else np.asarray(color, np.uint8),
                fill=np.zeros(n, bool) if fill is None else np.asarray(fill, bool),
            ),
        )
