"""The settling path's sleep (docs/models.md#stepped-gravity-restitution-and-friction): what a
settled scene does not need is skipped.

Input: the state (`records.Fall`, its `saved` holding where the step's pushes found each
object), the constants (`records.Physics`) and the step dt. Output: each awake object's time
below the rest speed and not pushed past SETTLED_PUSH_PX, and the objects that have been so for
`sleep_after` seconds put to sleep: velocity exactly 0, not moved, not paired with each other
(touch.py wakes one when a moving object touches it); settle.py then checks that none of them
fell asleep inside a static object (sunk.py). Without gravity the rest speed is 0 and nothing
sleeps; `sleep: false` makes `sleep_after` infinite.
"""

from __future__ import annotations

import math

from collide2d.engine.jit import njit
from collide2d.engine.models.stepped.move import B_VX, B_VY, B_X, B_Y

# An object the step's pushes (solver.correct) moved farther than this (px), beyond what a step
# of gravity sinks it (|g|·dt²), is still settling, however slow: it does not count toward sleep.
SETTLED_PUSH_PX = 1e-3


@njit(cache=True)
def doze(F, P, dt, fell):
    """Count each awake object's time below the rest speed and put to sleep those that have been
    below it for sleep_after s, marking each in `fell` ((n,) bool, which the caller clears);
    returns (how many objects are awake, how many fell asleep)."""
    body = F.body
    rest2 = P.rest * P.rest
    # what a step of gravity sinks an object into a support and its push takes back
    settled = SETTLED_PUSH_PX + math.hypot(P.gx, P.gy) * dt * dt
    awake = 0
    slept = 0
    for i in range(body.shape[0]):
        if not F.awake[i]:
            continue
        pushed = max(abs(body[i, B_X] - F.saved[i, 0]), abs(body[i, B_Y] - F.saved[i, 1]))
        slow = body[i, B_VX] * body[i, B_VX] + body[i, B_VY] * body[i, B_VY] < rest2
        if slow and pushed <= settled:
            F.quiet[i] += dt
        else:
            F.quiet[i] = 0.0
        if F.quiet[i] >= P.sleep_after:
            F.asleep[i] = True
            F.awake[i] = False
            body[i, B_VX] = 0.0
            body[i, B_VY] = 0.0
            fell[i] = True
            slept += 1
        else:
            awake += 1
    return awake, slept
