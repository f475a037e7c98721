"""boxflip: a collide2d model plugin written the way a user would — plain Python, no numba.

A fixed-step model of boxes with the flip rule of the paper ("elastic collision in 2D", section
II.E). Each tick of 1/fps s, every object in id order:

    move   x += vx / fps, y += vy / fps (static objects stay);
    walls  an object that left the world moving outward on an axis reverses that velocity
           component and takes back this tick's move on it;
    pairs  every overlapping pair of boxes in ascending (a, b) order, each seeing what the pairs
           before it changed: the overlap is xdiff wide and ydiff high; xdiff > ydiff reverses
           both vertical components (axis y), ydiff > xdiff both horizontal (axis x), a tie both
           (axis xy); then each object takes back its move of this tick on those axes.

Every shape collides as its box (SHAPES: box only, so a scenario with a circle is refused at its
line). Pairs are found by sort and sweep on x over each object's reach box (the hull of where it
was and where it moved to: a take-back only moves an object back within it), then tested on the
current positions in (a, b) order, exactly as the all-pairs loop would.

collide2d finds it through the entry point in pyproject.toml:

    [project.entry-points."collide2d.models"]
    boxflip = "boxflip:BoxFlip"

after which a scenario says `model: boxflip`.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.events import (
    AXIS_X,
    AXIS_XY,
    AXIS_Y,
    EV_PAIR,
    EV_WALL,
    EVENT_DTYPE,
    SIDE_BOTTOM,
    SIDE_LEFT,
    SIDE_RIGHT,
    SIDE_TOP,
)

__version__ = "0.1.0"


class BoxFlip:
    """The model: built from the scenario's world and bodies, advanced a number of ticks."""

    SHAPES = ("box",)  # the shapes it takes (the model protocol)
    OPTIONS = ()  # the scenario's model settings it takes: none

    def __init__(self, world, bodies):
        self.width, self.height, self.fps = world.width, world.height, world.fps
        self.pos = [list(map(float, p)) for p in bodies.pos]
        self.vel = [list(map(float, v)) for v in bodies.vel]
        self.size = [list(map(float, s)) for s in bodies.size]
        self.static = [bool(s) for s in bodies.static]
        self.before = self.pos  # where each object was before this tick's move
        self.tick = 0
        self.walls = 0
        self.pairs = 0

    # -- the protocol

    def advance(self, ticks: int, log: bool = True) -> np.ndarray:
        """Run `ticks` ticks; the events as EVENT_DTYPE records (none when `log` is False)."""
        events = []
        for _ in range(ticks):
            self.tick += 1
            moved = self._move()
            happened = self._walls(moved) + self._pairs(moved)
            if log:
                events.extend((self.tick, *event) for event in happened)
        out = np.zeros(len(events), dtype=EVENT_DTYPE)
        for i, (tick, kind, a, b, code) in enumerate(events):
            # t: the tick's end, s; xdiff, ydiff: -1 (they are the integer paper model's)
            out[i] = (tick, tick / self.fps, kind, a, b, code, -1, -1)
        return out

    def positions(self) -> np.ndarray:
        return np.array(self.pos, dtype=np.float64).reshape(-1, 2)

    def velocities(self) -> np.ndarray:
        return np.array(self.vel, dtype=np.float64).reshape(-1, 2)

    def event_counts(self) -> tuple[int, int]:
        return self.walls, self.pairs

    # -- one tick

    def _move(self) -> list[tuple[float, float]]:
        """Move every free object by its velocity over one tick; returns each one's move."""
        self.before = [p.copy() for p in self.pos]
        moved = []
        for i, (vx, vy) in enumerate(self.vel):
            if self.static[i]:
                moved.append((0.0, 0.0))
                continue
            dx, dy = vx / self.fps, vy / self.fps
            self.pos[i][0] += dx
            self.pos[i][1] += dy
            moved.append((dx, dy))
        return moved

    def _walls(self, moved) -> list[tuple]:
        """Objects that left the world moving outward bounce back: reverse, take back the move."""
        events = []
        for i in range(len(self.pos)):
            x, y = self.pos[i]
            w, h = self.size[i]
            for axis, low, high, limit in ((0, x, x + w, self.width), (1, y, y + h, self.height)):
                v = self.vel[i][axis]
                out_low, out_high = low < 0 and v < 0, high > limit and v > 0
                if out_low or out_high:
                    self.vel[i][axis] = -v
                    self.pos[i][axis] = self.before[i][axis]
                    side = (SIDE_LEFT, SIDE_RIGHT) if axis == 0 else (SIDE_TOP, SIDE_BOTTOM)
                    events.append((EV_WALL, i, -1, side[0] if out_low else side[1]))
                    self.walls += 1
        return events

    def _pairs(self, moved) -> list[tuple]:
        """The paper's flip on every overlapping pair, in (a, b) order."""
        events = []
        taken = [[False, False] for _ in self.pos]  # a move is taken back once per axis
        for a, b in self._candidates(moved):
            xdiff = _overlap(self.pos[a][0], self.size[a][0], self.pos[b][0], self.size[b][0])
            ydiff = _overlap(self.pos[a][1], self.size[a][1], self.pos[b][1], self.size[b][1])
            if xdiff <= 0 or ydiff <= 0:
                continue
            axes = (1,) if xdiff > ydiff else (0,) if ydiff > xdiff else (0, 1)
            for i in (a, b):
                for axis in axes:
                    if not self.static[i]:
                        self.vel[i][axis] = -self.vel[i][axis]
                    if not taken[i][axis]:
                        self.pos[i][axis] = self.before[i][axis]
                        taken[i][axis] = True
            code = AXIS_Y if axes == (1,) else AXIS_X if axes == (0,) else AXIS_XY
            events.append((EV_PAIR, a, b, code))
            self.pairs += 1
        return events

    def _candidates(self, moved) -> list[tuple[int, int]]:
        """Every pair whose reach boxes overlap, in (a, b) order (sort and sweep on x). An
        object's reach box holds it where it was before the move and where the move took it."""
        reach = []
        for i, (start, size, move) in enumerate(zip(self.before, self.size, moved, strict=True)):
            box = []
            for axis in (0, 1):
                end = start[axis] + move[axis]
                box += [min(start[axis], end), max(start[axis], end) + size[axis]]
            reach.append((*box, i))
        reach.sort()
        found = []
        for k, (_x0, x1, y0, y1, i) in enumerate(reach):
            for u0, _u1, v0, v1, j in reach[k + 1 :]:
                if u0 >= x1:
                    break
                if v0 < y1 and y0 < v1 and not (self.static[i] and self.static[j]):
                    found.append((min(i, j), max(i, j)))
        return sorted(found)


def _overlap(p: float, s: float, q: float, t: float) -> float:
    """How far the intervals [p, p + s) and [q, q + t) overlap (<= 0: apart or touching)."""
    return min(p + s, q + t) - max(p, q)
