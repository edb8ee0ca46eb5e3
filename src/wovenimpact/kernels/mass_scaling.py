"""Selective mass scaling (docs/theory.md §4, "Mass scaling"; LS-DYNA's DT2MS < 0).

An element whose own stable step Δt_e = L_e/c_e falls below a target Δt* gets mass
added so that its step is the target again: c_e ∝ 1/√μ, so scaling the element's mass
by (1 + r_e) scales its step by √(1 + r_e), and

    r_e = max(r_e, (Δt*/Δt_e)² − 1)                                    (mass ratio)

(never lowered: mass, once added, stays). A node carries a quarter of the added mass
of each of its elements, its rotary inertia scaled by the same factor as its mass:

    m_n = m_n0 + ¼ Σ_e r_e m_e,    I_n = I_n0 m_n / m_n0.

Mass added to a moving node, at its velocity, adds ½ Δm v·v + ½ ΔI ω·ω of kinetic
energy, which the energy balance books as an input (``MASS_SCALING`` of the State).
Both kernels are deterministic: a minimum and a count (exact in any order), per-node sums
in CSR order.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import loop_kernel


@loop_kernel
def scale_element_masses(elem, col_dt, col_kin, alive, ratio, dt_target):
    """Raise r_e of the live elements whose scaled step Δt_e √(1 + r_e) is below
    ``dt_target`` (same units as ``elem[:, col_dt]``: L_e/c_e, before the factor α).
    ``elem[:, col_kin]`` is each element's kinematic bound (∞ where there is none): it
    depends on the motion alone, so it gets no mass (mass added for it would not raise
    the step) but still bounds the step.

    Returns (number of elements raised, min over live elements of Δt_e √(1 + r_e) and
    of their kinematic bounds). Elements with a step of 0 or inf (failed, eroded) are
    left alone.
    """
    raised = 0
    dt_min = math.inf
    for e in prange(elem.shape[0]):  # (a count and a minimum: exact in any order)
        if alive[e] == 0:
            continue
        d = elem[e, col_dt]
        if not (d > 0.0) or not math.isfinite(d):
            dt_min = min(dt_min, min(elem[e, col_kin], d))
            continue
        scaled = d * math.sqrt(1.0 + ratio[e])
        if scaled < dt_target:
            q = dt_target / d
            ratio[e] = q * q - 1.0
            scaled = dt_target
            raised += 1
        dt_min = min(dt_min, min(elem[e, col_kin], scaled))
    return raised, dt_min


@loop_kernel
def scaled_node_masses(node_ptr, node_elem, ratio, elem_mass, mass0, inertia0, v, omega,
                       added, mass, inertia, added_ke):
    """Added mass ¼ Σ_e r_e m_e into ``added``, m_n = m_n0 + added and I_n = I_n0 m_n/m_n0
    into ``mass`` and ``inertia`` (which hold the previous values), and the kinetic energy
    each node gains, ½ Δm v·v + ½ ΔI ω·ω, into ``added_ke`` (J). The same expressions
    rebuild the masses from ``added`` on a restart (:func:`node_masses`), bit for bit."""
    for n in prange(mass0.shape[0]):
        extra = 0.0
        for k in range(node_ptr[n], node_ptr[n + 1]):
            e = node_elem[k]
            extra += 0.25 * ratio[e] * elem_mass[e]
        added[n] = extra
        m_new = mass0[n] + extra
        i_new = inertia0[n] * (m_new / mass0[n]) if mass0[n] > 0.0 else inertia0[n]
        dm = m_new - mass[n]
        di = i_new - inertia[n]
        added_ke[n] = 0.5 * dm * (v[n, 0] * v[n, 0] + v[n, 1] * v[n, 1] + v[n, 2] * v[n, 2]) + (
            0.5 * di * (omega[n, 0] * omega[n, 0] + omega[n, 1] * omega[n, 1]
                        + omega[n, 2] * omega[n, 2])
        )
        mass[n] = m_new
        inertia[n] = i_new


def node_masses(mass0, inertia0, added):
    """(m, I) of the nodes with the mass ``added`` by scaling (NumPy; a run's start or
    restart): the expressions of :func:`scaled_node_masses`, so a restart is bitwise."""
    mass = mass0 + added
    with np.errstate(divide="ignore", invalid="ignore"):
        inertia = np.where(mass0 > 0.0, inertia0 * (mass / mass0), inertia0)
    return mass, inertia
