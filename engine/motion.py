"""Moving objects: the paper's integer counters (docs/models.md#paper-motion, paper section II.D)
and float drift.

The paper moves an object by a whole step of `V` pixels every `P` ticks. `paper_rate` finds that
step for a velocity v (px/s) at `fps` ticks per second: `V/P = v/fps` in lowest terms, computed
exactly from the decimal the user wrote (7.5 px/s at 10 fps is 3 px every 4 ticks). The counters
themselves run inside the paper model's kernel.
"""

from __future__ import annotations

import math
from fractions import Fraction

# The longest period the paper model accepts: a velocity needing more ticks than this between
# steps is refused as not a whole number of pixels per whole number of ticks.
MAX_PERIOD_TICKS = 1_000_000


def paper_rate(v: float, fps: int) -> tuple[int, int]:
    """(V, P): move V whole pixels every P ticks, V/P = v/fps in lowest terms, P >= 1.

    Raises ValueError with a user-facing message when v is not finite or needs a period longer than
    MAX_PERIOD_TICKS.
    """
    if isinstance(v, bool) or not math.isfinite(float(v)):
        raise ValueError(f"velocity {v!r} is not a finite number")
    exact = Fraction(v) if isinstance(v, int) else Fraction(repr(float(v)))
    rate = exact / Fraction(fps)
    if rate.denominator > MAX_PERIOD_TICKS:
        raise ValueError(
            f"velocity {v!r} px/s at {fps} fps is not a whole number of pixels per whole number of "
            f"ticks (it would need {rate.numerator} px every {rate.denominator} ticks; the paper "
            f"model allows at most {MAX_PERIOD_TICKS} ticks per step)"
        )
    return rate.numerator, rate.denominator
