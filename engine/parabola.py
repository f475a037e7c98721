"""Motion under a uniform acceleration, shared by the models that have gravity: the first instant
a gap closes, and the acceleration of a body sliding on a wall
(docs/models.md#stepped-gravity-restitution-and-friction, docs/models.md#exact-under-gravity).

Each axis of a body under gravity is a 1-D motion of constant acceleration, `p + v·t + ½·a·t²`,
exact for uniform gravity. A gap h >= 0 to something that does not share that acceleration (a
wall, a grid line) closes at a quadratic's root, taken in its cancellation-free form (v the
gap's rate, negative while closing; a its acceleration): closing, `t = 2h / (-v + √(v² - 2ah))`;
opening and pulled back, `t = (v + √(v² - 2ah)) / -a`. A gap of 0 that opens gives the later
root exactly, never a rounded instant near 0.
"""

from __future__ import annotations

import math

import numpy as np

from collide2d.engine.jit import njit

INF = np.inf


@njit(cache=True, inline="always")
def meet(h, v, a):
    """The first instant >= 0 at which a gap h >= 0 closing at rate v (< 0 closing), with
    acceleration a, is 0; inf when never (module docstring)."""
    if h <= 0.0 and (v < 0.0 or (v == 0.0 and a < 0.0)):
        return 0.0
    if v < 0.0:
        disc = v * v - 2.0 * a * h
        if disc < 0.0:
            return INF
        return 2.0 * h / (-v + math.sqrt(disc))
    if a < 0.0:
        return (v + math.sqrt(v * v - 2.0 * a * h)) / -a
    return INF


@njit(cache=True, inline="always")
def slide_acceleration(g, v, mu, pull):
    """The acceleration along a wall of a body resting on it: gravity along it, g, less friction
    against the motion, mu times `pull` (gravity's pull into the wall, >= 0); at rest, static
    friction holds it when strong enough, else it starts sliding the way gravity pulls."""
    grip = mu * pull
    if v > 0.0:
        return g - grip
    if v < 0.0:
        return g + grip
    if abs(g) <= grip:
        return 0.0
    return g - grip if g > 0.0 else g + grip
