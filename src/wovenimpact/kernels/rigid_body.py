"""Rigid-body dynamics of impactors, central differences like the nodes (docs/model.md §4).

State row of a body (``State.bodies``, layout below): centre-of-mass position x^n,
velocity v^{n−1/2}, rotation matrix R^n (body → global, row-major) and body-frame
spin ω_b^{n−1/2}. With the resultant force F and torque τ (global, about the centre
of mass) at t^n:

    v^{n+1/2} = v^{n−1/2} + Δt^n F / m,            x^{n+1} = x^n + Δt^{n+1/2} v^{n+1/2},
    ω_b^{n+1/2} = ω_b^{n−1/2} + Δt^n I⁻¹ (Rᵀτ − ω_b × I ω_b),
    R^{n+1} = R^n exp(Δt^{n+1/2} [ω_b^{n+1/2}]×)   (Rodrigues; R stays orthonormal),

with I = diag(I_axial, I_t, I_t) in the body frame whose first axis is the axis of
revolution (tip → tail). Euler's gyroscopic term is explicit (first order; bodies of
revolution spinning about their axis feel none).
"""

from __future__ import annotations

import math

from wovenimpact.jit import kernel

B_X = 0  # centre of mass (3)
B_V = 3  # velocity (3)
B_R = 6  # rotation matrix body → global (9, row-major)
B_W = 15  # body-frame angular velocity (3)
B_F = 18  # contact force on the body at the last whole step (3, for its work)
N_BODY_STATE = 21

# static parameters of a body (Model.body_params)
BP_MASS = 0  # m (kg)
BP_I_AXIAL = 1  # moment of inertia about the axis of revolution (kg m²)
BP_I_TRANS = 2  # about a transverse axis through the centre of mass (kg m²)
BP_TIP = 3  # distance from the nose tip to the centre of mass along the axis (m)
BP_BETA = 4  # penalty factor β of k = β m_node / Δt²
BP_REACH = 5  # radius of a sphere about the tip enclosing the body (m)
BP_NPTS = 6  # number of profile points used in Model.body_profiles
BP_AXIAL_ONLY = 7  # 1: the body moves along its axis only (symmetry planes through it)
BP_FRACTION = 8  # share of the body in the model (0.25 in a quarter model)
BP_DAMPING = 9  # contact damping ζ, fraction of critical of each node–body pair
BP_FRICTION = 10  # Coulomb coefficient μ between the body and the nodes
N_BODY_PARAM = 11


@kernel
def advance_body(s, mass, i_axial, i_trans, force, torque, dt_old, dt_new):
    """Advance one body state row ``s`` in place (module docstring). Returns the
    kinetic energy ½ m v^{n−1/2}·v^{n+1/2} + ½ ω_b^{n−1/2}·I ω_b^{n+1/2} at t^n."""
    dt_mid = 0.5 * (dt_old + dt_new)
    ke = 0.0
    for d in range(3):
        old = s[B_V + d]
        new = old + dt_mid * force[d] / mass
        ke += 0.5 * mass * old * new
        s[B_V + d] = new
        s[B_X + d] += dt_new * new
    # torque in the body frame: τ_b = Rᵀ τ
    tb0 = s[B_R + 0] * torque[0] + s[B_R + 3] * torque[1] + s[B_R + 6] * torque[2]
    tb1 = s[B_R + 1] * torque[0] + s[B_R + 4] * torque[1] + s[B_R + 7] * torque[2]
    tb2 = s[B_R + 2] * torque[0] + s[B_R + 5] * torque[1] + s[B_R + 8] * torque[2]
    w0, w1, w2 = s[B_W], s[B_W + 1], s[B_W + 2]
    inertia = (i_axial, i_trans, i_trans)
    lw0, lw1, lw2 = i_axial * w0, i_trans * w1, i_trans * w2
    gyro = (w1 * lw2 - w2 * lw1, w2 * lw0 - w0 * lw2, w0 * lw1 - w1 * lw0)
    tb = (tb0, tb1, tb2)
    for d in range(3):
        old = s[B_W + d]
        new = old + dt_mid * (tb[d] - gyro[d]) / inertia[d]
        ke += 0.5 * inertia[d] * old * new
        s[B_W + d] = new
    # R ← R exp(Δt [ω]×)
    wx, wy, wz = s[B_W] * dt_new, s[B_W + 1] * dt_new, s[B_W + 2] * dt_new
    th = math.sqrt(wx * wx + wy * wy + wz * wz)
    if th > 0.0:
        kx, ky, kz = wx / th, wy / th, wz / th
        c, sn = math.cos(th), math.sin(th)
        v = 1.0 - c
        q = (
            c + kx * kx * v, kx * ky * v - kz * sn, kx * kz * v + ky * sn,
            ky * kx * v + kz * sn, c + ky * ky * v, ky * kz * v - kx * sn,
            kz * kx * v - ky * sn, kz * ky * v + kx * sn, c + kz * kz * v,
        )
        r = (s[B_R + 0], s[B_R + 1], s[B_R + 2], s[B_R + 3], s[B_R + 4], s[B_R + 5],
             s[B_R + 6], s[B_R + 7], s[B_R + 8])
        for i in range(3):
            for j in range(3):
                s[B_R + 3 * i + j] = (r[3 * i] * q[j] + r[3 * i + 1] * q[3 + j]
                                      + r[3 * i + 2] * q[6 + j])
    return ke
