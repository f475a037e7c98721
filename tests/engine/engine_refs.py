"""Reference helpers shared by the engine's tests: scenes and plain geometry written apart from
the code under test."""

import numpy as np

from collide2d.engine.world import Bodies


def random_boxes(n, seed, world, size=8.0, speed=60.0, mass_range=(0.2, 5.0)):
    """n boxes on a jittered grid (no overlap), random velocities and masses."""
    rng = np.random.default_rng(seed)
    k = int(np.ceil(np.sqrt(n)))
    pitch = np.array([world.width, world.height]) / k
    idx = np.arange(n)
    cells = np.stack([idx % k, idx // k], axis=1)
    pos = cells * pitch + rng.uniform(0, 1, (n, 2)) * (pitch - size)
    vel = rng.uniform(-speed, speed, (n, 2))
    return Bodies.boxes(pos, size, vel, mass=rng.uniform(*mass_range, n))


def ref_hull(points):
    """Convex hull (positive order, no collinear points) by a plain monotone chain."""
    pts = sorted(set(map(tuple, np.asarray(points, float).tolist())))
    if len(pts) < 3:
        return np.array(pts)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def pixel_corners(verts):
    v = np.asarray(verts, float)
    return (v[:, None, :] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]])[None]).reshape(-1, 2)


def pile_bodies(n, seed, width, size=8.0, pitch=10.0, e=0.3, mu=0.3, speed=20.0):
    """n objects, boxes and circles in turn (sides size, px), on a jittered grid of `pitch` px
    from the top of a world `width` px wide, at small random speeds: a pile about to be dropped.
    Every object has restitution e and friction mu."""
    from collide2d.engine.world import KIND_CIRCLE, Looks

    rng = np.random.default_rng(seed)
    cols = int(width // pitch)
    idx = np.arange(n)
    pos = np.stack([idx % cols, idx // cols], axis=1) * pitch
    pos = pos + rng.uniform(0, pitch - size, (n, 2))
    kind = np.where(idx % 2 == 1, KIND_CIRCLE, 0).astype(np.int8)
    return Bodies(
        kind=kind,
        pos=pos,
        size=np.full((n, 2), size),
        vel=rng.uniform(-speed, speed, (n, 2)),
        mass=rng.uniform(0.5, 2.0, n),
        static=np.zeros(n, bool),
        vert_start=np.zeros(n + 1, np.int64),
        verts=np.zeros((0, 2), np.int64),
        looks=Looks(color=np.ones(n, np.uint8), fill=np.zeros(n, bool)),
        restitution=np.full(n, float(e)),
        friction=np.full(n, float(mu)),
    )
