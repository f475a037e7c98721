"""collide2d's simulation engine: arrays in, arrays and events out, no I/O.

`world` holds the per-object arrays, `models` the three rule sets (paper, stepped, exact),
`raster` turns positions into frames, and `events` fixes how an event is recorded and written.
"""
