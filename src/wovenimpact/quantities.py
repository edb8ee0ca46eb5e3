"""Engineering quantities of a run: impactor kinematics, residual velocity, energies by ply.

Models with symmetry planes carry a share of the impactor (a quarter in a quarter
model, ``kernels.rigid_body.BP_FRACTION``); forces and energies returned here as
"full" are the whole-problem values (divided by that share), velocities are the same.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels import shell_layout as S

QUIET_TIME = 10e-6  # contact must have been light this long to call a perforation
LIGHT_CONTACT = 0.01  # "light": below this fraction of the peak contact force
STEADY_VELOCITY = 1e-3  # or the velocity changed by less than this fraction over it


def symmetry_factor(model) -> float:
    """1 / (share of the first impactor in the model): 4 in a quarter model, else 1."""
    if model.body_params.shape[0] == 0:
        return 1.0
    return 1.0 / model.body_params[0, RB.BP_FRACTION]


def travel_direction(model, state, b: int = 0) -> np.ndarray:
    """Unit vector of the body's direction of travel (tip leading): −(body axis)."""
    return -state.bodies[b, RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0]


def impactor_row(model, state, b: int = 0) -> dict:
    """Velocity and displacement along the initial travel direction, and the contact
    force resisting it (full-problem value), of impactor b."""
    d0 = -model.body_state0[b, RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0]
    row = state.bodies[b]
    x0 = model.body_state0[b, RB.B_X:RB.B_X + 3]
    factor = 1.0 / model.body_params[b, RB.BP_FRACTION]
    return {
        "impactor_velocity_m_per_s": float(row[RB.B_V:RB.B_V + 3] @ d0),
        "impactor_displacement_m": float((row[RB.B_X:RB.B_X + 3] - x0) @ d0),
        "contact_force_N": float(-(row[RB.B_F:RB.B_F + 3] @ d0) * factor),
    }


def residual_velocity(h: dict, quiet_time: float = QUIET_TIME) -> dict:
    """Outcome of an impact from the impactor columns of a history.

    - stopped: the impactor's velocity along its travel reached zero; residual 0, and
      the speed it bounced back with is reported as ``rebound_velocity_m_per_s``;
    - perforated: still moving forward, and for the last ``quiet_time`` the contact force
      has stayed below 1 % of its peak or the velocity has changed by less than 0.1 %
      (torn yarns may still rub the shank; debris may strike it from behind);
      residual = its final velocity;
    - undecided: still moving forward and still (or recently) in contact: run longer;
    - no contact: the impactor never touched anything (e.g. through a hole).
    """
    t = h["time_s"]
    v = h["impactor_velocity_m_per_s"]
    f = h["contact_force_N"]
    v_end = float(v[-1])
    if np.min(v) <= 0.0:
        return {"outcome": "stopped", "perforated": False, "residual_velocity_m_per_s": 0.0,
                "rebound_velocity_m_per_s": max(0.0, -v_end)}
    touching = np.flatnonzero(np.abs(f) > 0.0)
    if not touching.size:
        return {"outcome": "no contact", "perforated": True, "residual_velocity_m_per_s": v_end,
                "rebound_velocity_m_per_s": 0.0}
    # rubbing of torn yarns on the shank is not an engagement: below 1 % of the peak,
    # or too little to change the velocity (by 0.1 %) over the quiet time; nor is debris
    # striking it from behind (a force along the travel, f < 0)
    engaged = np.flatnonzero(f > LIGHT_CONTACT * np.max(np.abs(f)))
    if not engaged.size:
        engaged = touching
    quiet = t[-1] - t[engaged[-1]]
    window = t >= t[-1] - quiet_time
    steady = (t[-1] - t[0] >= quiet_time
              and np.ptp(v[window]) <= STEADY_VELOCITY * abs(v_end))
    if quiet >= quiet_time or steady:
        return {"outcome": "perforated", "perforated": True, "residual_velocity_m_per_s": v_end,
                "rebound_velocity_m_per_s": 0.0}
    return {"outcome": "undecided (still in contact: run longer)", "perforated": False,
            "residual_velocity_m_per_s": v_end, "rebound_velocity_m_per_s": 0.0}


def ply_energies(model, state) -> list[float]:
    """Energy held by each ply (full-problem values, J): kinetic energy of its nodes plus
    the stored energy of its elements (for eroded elements, the energy at erosion).
    Energy dissipated by yarns that broke in elements that did not erode is not in it."""
    factor = symmetry_factor(model)
    out = []
    for p in np.unique(model.ply):
        elems = np.flatnonzero(model.ply == p)
        nodes = np.unique(model.quads[elems])
        ke = 0.5 * float(np.sum(model.node_mass[nodes] * np.sum(state.v[nodes] ** 2, axis=1)))
        stored = float(np.sum(state.elem[elems, S.E_U_MEMB] + state.elem[elems, S.E_U_BEND]
                              + state.elem[elems, S.E_U_HG]))
        out.append(factor * (ke + stored))
    return out


def ply_deflections(model, state) -> list[float]:
    """Largest displacement of each ply's nodes (m)."""
    out = []
    for p in np.unique(model.ply):
        nodes = np.unique(model.quads[model.ply == p])
        out.append(float(np.sqrt(np.max(np.sum((state.x[nodes] - model.x0[nodes]) ** 2, axis=1)))))
    return out
