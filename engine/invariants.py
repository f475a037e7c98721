"""What a state keeps or must not break: kinetic and potential energy, momentum, the deepest overlap
of two boxes.

One definition of each, shared by the run summary (runner.run), the stress checks (runner.stress),
the benchmark's error measures (runner.bench) and the engine's tests. All take the arrays of
`engine.world.Bodies` and a model's state: mass (n,) float64 (inf for statics), static (n,) bool,
vel and pos (n, 2) float64 (px/s, px), size (n, 2) float64 px. Energy and momentum count movable
objects only; they are in px units per unit mass. `energy_momentum` is the kernel (numba, also
callable from other kernels, as the stress checks do); `kinetic_energy` and `momentum` are its
whole-array forms. `potential_energy` is the energy of position in uniform gravity g (px/s², y
down) relative to the world's origin, U = -sum m (g . c) over movable objects, c the centre of
each object's box (docs/outputs.md#summary): with g = [0, 980] a body 10 px lower has 9800 m less.
Kinetic plus potential is the total the models keep (elastic, frictionless) or lose, never gain.
"""

from __future__ import annotations

import numpy as np

from collide2d.engine.jit import njit


@njit(cache=True)
def energy_momentum(mass, static, vel):
    """(kinetic energy sum m|v|^2/2, momentum x, momentum y) over movable objects, summed in id
    order.

    A velocity past about 1e154 px/s gives inf (no floating-point warning, for the caller to
    judge); a value that is not finite passes through.
    """
    energy = 0.0
    px = 0.0
    py = 0.0
    for i in range(vel.shape[0]):
        if static[i]:
            continue
        m = mass[i]
        vx = vel[i, 0]
        vy = vel[i, 1]
        energy += 0.5 * m * (vx * vx + vy * vy)
        px += m * vx
        py += m * vy
    return energy, px, py


def _figures(mass, static, vel) -> tuple[float, float, float]:
    return energy_momentum(
        np.ascontiguousarray(mass, np.float64),
        np.ascontiguousarray(static, np.bool_),
        np.ascontiguousarray(vel, np.float64).reshape(-1, 2),
    )


def kinetic_energy(mass: np.ndarray, static: np.ndarray, vel: np.ndarray) -> float:
    """Total kinetic energy, sum of m|v|^2/2 over movable objects (px^2/s^2 per unit mass).

    Finite for every scenario the loader accepts (its mass and speed bounds see to it); a velocity
    past about 1e154 px/s would give inf, returned without a floating-point warning for the caller
    to judge. Never -0.0.
    """
    return float(_figures(mass, static, vel)[0]) + 0.0


def momentum(mass: np.ndarray, static: np.ndarray, vel: np.ndarray) -> tuple[float, float]:
    """Total momentum (px/s per unit mass) over movable objects; finite like `kinetic_energy`,
    never -0.0."""
    _, px, py = _figures(mass, static, vel)
    return float(px) + 0.0, float(py) + 0.0


def potential_energy(mass, static, pos, size, gravity) -> float:
    """Total potential energy in uniform `gravity` (gx, gy) px/s², relative to the world's origin:
    -sum of m (g . c) over movable objects, c = pos + size / 2 the centre of each box (px^2/s^2
    per unit mass). Exactly 0.0 without gravity, whatever the positions; never -0.0."""
    gx, gy = float(gravity[0]), float(gravity[1])
    if gx == 0.0 and gy == 0.0:
        return 0.0
    movable = ~np.asarray(static, np.bool_)
    m = np.asarray(mass, np.float64)[movable]
    c = (np.asarray(pos, np.float64) + 0.5 * np.asarray(size, np.float64)).reshape(-1, 2)[movable]
    return float(-np.sum(m * (gx * c[:, 0] + gy * c[:, 1]))) + 0.0


def energies(bodies, pos, vel, gravity) -> tuple[float, float, float]:
    """(kinetic, potential, their sum) of `bodies` (engine.world.Bodies: mass, static, size) at
    positions `pos` and velocities `vel` (n, 2), in `gravity` (gx, gy) px/s²."""
    kinetic = kinetic_energy(bodies.mass, bodies.static, vel)
    potential = potential_energy(bodies.mass, bodies.static, pos, bodies.size, gravity)
    return kinetic, potential, kinetic + potential + 0.0


@njit(cache=True)
def max_penetration(pos, size):
    """(depth px, a, b): the deepest overlap of two boxes, min(overlap width, overlap height).

    pos, size (n, 2) float64, px. Sort-and-sweep on x: cost n log n plus the pairs whose x
    intervals meet. Touching boxes have depth 0. (0.0, -1, -1) when no two boxes overlap.
    """
    n = pos.shape[0]
    order = np.argsort(pos[:, 0], kind="mergesort")
    worst = 0.0
    wa = -1
    wb = -1
    for k in range(n):
        i = order[k]
        xi = pos[i, 0]
        yi = pos[i, 1]
        ri = xi + size[i, 0]
        bi = yi + size[i, 1]
        for m in range(k + 1, n):
            j = order[m]
            xj = pos[j, 0]
            if xj >= ri:
                break
            ox = min(ri, xj + size[j, 0]) - max(xi, xj)
            oy = min(bi, pos[j, 1] + size[j, 1]) - max(yi, pos[j, 1])
            d = min(ox, oy)
            if d > worst:
                worst = d
                wa = min(i, j)
                wb = max(i, j)
    return worst, wa, wb
