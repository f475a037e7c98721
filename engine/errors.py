"""The ways a model stops a run: one base class, `Runaway`, for every "this run cannot go on" case.

A runaway is a scene the model cannot carry forward in bounded work: the exact model's event cap
(`EventCapExceeded`: more than `max_events_per_tick` events in one tick), an object with no room to
move on an axis (`NoRoom`: under the exact model it would collide again and again without time
passing), the stepped model's fold limit (`FoldLimitExceeded`: an object crossing the world too
many times in one step), and what the exact model cannot carry on yet (`NotYetExact`: under
gravity, a body that comes to rest on a static object or another body). Callers catch `Runaway`
and show `str(err)`, which says what stopped and why; the engine never prints.
`FoldLimitExceeded` is raised inside a compiled kernel, so its message is a constant.
"""

from __future__ import annotations


class Runaway(Exception):
    """A model stopped the run: the scene cannot be carried on in bounded work."""


class EventCapExceeded(Runaway, RuntimeError):
    """A tick needed more events than `max_events_per_tick` allows (exact model)."""


class NoRoom(Runaway, ValueError):
    """An object moves on an axis along which it has no room at all (exact model): it is as wide
    as the space between the walls or static objects around it, so it would collide again and
    again at one instant. `objects` lists the ids involved, `axis` is "x" or "y"."""

    def __init__(self, message: str, objects: tuple[int, ...] = (), axis: str = ""):
        super().__init__(message)
        self.objects = tuple(objects)
        self.axis = axis


class FoldLimitExceeded(Runaway, ValueError):
    """An object crosses the world too many times in one step (stepped model)."""


class NotYetExact(Runaway, RuntimeError):
    """The exact model met what it does not yet carry on exactly (a body that comes to rest on a
    static object or another body under gravity); `objects` lists the ids involved."""

    def __init__(self, message: str, objects: tuple[int, ...] = ()):
        super().__init__(message)
        self.objects = tuple(objects)
