"""A scenario as a pymunk space, stepped tick by tick, with the events of the event log.

Each object is a pymunk body at the centre of its box with an infinite moment (no rotation): a
box is a `Poly.create_box`, a circle a `Circle`, a polygon a `Poly` of its vertices (pymunk takes
their convex hull). Static objects are static bodies. The world's walls are four static segments
along its edges. A contact's first tick (pymunk's `begin`) is an event at the tick's end, like
the stepped model's: a wall event naming the object and the side, or a pair event with the axis of
the contact normal (`n` when it is not along x or y); within a tick, walls first, then pairs, each
in id order. The counts are kept whether events are logged or not; `events=False` installs no
callback at all (what the bench times: pymunk's own speed).
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.events import (
    AXIS_NORMAL,
    AXIS_X,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    EVENT_DTYPE,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
)
from collide2d.engine.world import KIND_BOX, KIND_CIRCLE, KIND_NAMES, Bodies, WorldSpec

# A contact normal component smaller than this counts as zero (the axis of a pair event).
AXIS_EPS = 1e-9


def _pymunk():
    try:
        import pymunk
    except ImportError:
        raise ImportError(
            "pymunk is not installed; it comes with the bench extra: "
            "pip install 'collide2d[bench]'"
        ) from None
    return pymunk


class Model:
    """The scene in a pymunk space (see the module docstring). `spatial_hash`: (cell size px,
    cell count) for pymunk's spatial hash instead of its bounding-box tree; `events`: False
    counts and logs nothing (no collision callback)."""

    SHAPES = KIND_NAMES
    OPTIONS = ()

    def __init__(self, world: WorldSpec, bodies: Bodies, *, spatial_hash=None, events=True):
        pymunk = _pymunk()
        self.world = world
        self.dt = 1.0 / world.fps
        self.tick = 0
        self.n = bodies.n
        self.space = space = pymunk.Space()
        space.gravity = tuple(float(g) for g in world.gravity)
        if spatial_hash is not None:
            space.use_spatial_hash(*spatial_hash)
        self._half = bodies.size / 2.0
        self._ids: dict = {}  # shape -> object id, or -1 - side for a wall
        self._add_walls(pymunk, world)
        self.bodies = [self._add(pymunk, bodies, i) for i in range(bodies.n)]
        self._walls = self._pairs = 0
        self._happened: list = []
        if events:
            space.on_collision(begin=self._begin)

    def _add_walls(self, pymunk, world: WorldSpec) -> None:
        w, h = world.width, world.height
        sides = (
            (SIDE_TOP, (0, 0), (w, 0)),
            (SIDE_RIGHT, (w, 0), (w, h)),
            (SIDE_BOTTOM, (w, h), (0, h)),
            (SIDE_LEFT, (0, h), (0, 0)),
        )
        for side, a, b in sides:
            wall = pymunk.Segment(self.space.static_body, a, b, 0.0)
            wall.elasticity = float(world.restitution)
            wall.friction = float(world.friction)
            self.space.add(wall)
            self._ids[wall] = -1 - side

    def _add(self, pymunk, bodies: Bodies, i: int):
        (x, y), (w, h) = bodies.pos[i], bodies.size[i]
        if bodies.static[i]:
            body = pymunk.Body(body_type=pymunk.Body.STATIC)
        else:
            body = pymunk.Body(float(bodies.mass[i]), math.inf)
            body.velocity = (float(bodies.vel[i, 0]), float(bodies.vel[i, 1]))
        body.position = (float(x + w / 2), float(y + h / 2))
        kind = int(bodies.kind[i])
        if kind == KIND_BOX:
            shape = pymunk.Poly.create_box(body, (float(w), float(h)))
        elif kind == KIND_CIRCLE:
            shape = pymunk.Circle(body, float(w) / 2)
        else:
            verts = bodies.verts[bodies.vert_start[i] : bodies.vert_start[i + 1]]
            shape = pymunk.Poly(body, [(float(px - w / 2), float(py - h / 2)) for px, py in verts])
        shape.elasticity = float(bodies.restitution[i])
        shape.friction = float(bodies.friction[i])
        self.space.add(body, shape)
        self._ids[shape] = i
        return body

    def _begin(self, arbiter, space, data) -> None:
        a, b = (self._ids[s] for s in arbiter.shapes)
        if a < 0 or b < 0:  # a wall: the other shape is the object
            obj, wall = (b, a) if a < 0 else (a, b)
            self._happened.append((EV_WALL, obj, -1, -1 - wall))
            self._walls += 1
            return
        nx, ny = arbiter.normal
        axis = AXIS_X if abs(ny) < AXIS_EPS else AXIS_Y if abs(nx) < AXIS_EPS else AXIS_NORMAL
        self._happened.append((EV_PAIR, min(a, b), max(a, b), axis))
        self._pairs += 1

    # -- the protocol

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Step the space `ticks` times; the events (EVENT_DTYPE) when `log`."""
        rows = []
        for _ in range(int(ticks)):
            self.space.step(self.dt)
            self.tick += 1
            if self._happened:
                if log:
                    rows.extend((self.tick, *e) for e in sorted(self._happened))
                self._happened.clear()
        out = np.zeros(len(rows), dtype=EVENT_DTYPE)
        for k, (tick, kind, a, b, code) in enumerate(rows):
            out[k] = (tick, tick * self.dt, kind, a, b, code, -1, -1)
        return out

    def positions(self) -> np.ndarray:
        centres = np.array([tuple(b.position) for b in self.bodies], np.float64)
        return centres.reshape(-1, 2) - self._half

    def velocities(self) -> np.ndarray:
        return np.array([tuple(b.velocity) for b in self.bodies], np.float64).reshape(-1, 2)

    def event_counts(self) -> tuple[int, int]:
        return self._walls, self._pairs
