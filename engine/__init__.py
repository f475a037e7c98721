"""collide2d's simulation engine: arrays in, arrays and events out, no I/O.

`world` holds the per-object arrays, `models` the three rule sets (paper, stepped, exact), one
package each, `picture` turns positions into frames, and `events` fixes how an event is recorded
and written. The modules at this level are what the models share (contact geometry, response,
broad phase, sorting, threads, the event log); they may import numpy and each other, never a
model's package nor the picture stage, and nothing in the engine imports `collide2d.runner`.
"""
