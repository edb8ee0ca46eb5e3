"""The force of one contact pair: penalty spring, dashpot and Coulomb friction
(docs/theory.md §6.2–6.3), shared by the impactor and the shell–shell contact."""

from __future__ import annotations

import math

from wovenimpact.jit import kernel


@kernel
def pair_force(spring, c, vx, vy, vz, nx, ny, nz, mu, m, dt):
    """Force on the node of a pair with unit normal n (towards the node):

        f_n = spring − c v_n                     (v_n = v_r · n, v_r the relative velocity)
        f_t = −min(μ |f_n|, ½ m |v_t| / Δt) v_t/|v_t|   (kinetic friction, capped so that
                                                  it removes at most half the relative
                                                  tangential velocity in one step)

    ``spring`` is the penalty force k g (≥ 0), ``c`` the dashpot coefficient, ``m`` the
    pair's mass for the friction cap. Returns (f_x, f_y, f_z)."""
    vn = vx * nx + vy * ny + vz * nz
    f_n = spring - c * vn
    fx, fy, fz = f_n * nx, f_n * ny, f_n * nz
    if mu > 0.0:
        tx, ty, tz = vx - vn * nx, vy - vn * ny, vz - vn * nz
        vt = math.sqrt(tx * tx + ty * ty + tz * tz)
        if vt > 0.0:
            f_t = min(mu * abs(f_n), 0.5 * m * vt / dt)
            fx -= f_t * tx / vt
            fy -= f_t * ty / vt
            fz -= f_t * tz / vt
    return fx, fy, fz
