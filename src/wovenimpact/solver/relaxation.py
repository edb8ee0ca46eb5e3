"""Steady spin state of a rotating structure by dynamic relaxation (docs/theory.md §8.1).

The thesis spins its fan blade up from rest over 9 s of implicit dynamics to get the
centrifugal pre-stress and the nodal velocities at 1047 rad/s (its §8.2). The steady
state is reached in seconds here: in the frame turning with the blade the pre-stress is
the static equilibrium under the centrifugal body force ω² r⊥ (r⊥ the distance from
the spin axis), found by explicit dynamics with kinetic damping (past each peak of the
kinetic energy every node is stopped where that step began, so the motion settles in
the equilibrium);
the inertial state at t = 0 is that configuration and stress with the rigid-rotation
velocities v = ω × (x − c) and spins ω added (:func:`spin_state`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wovenimpact.errors import SimulationError
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.state import State


def centrifugal_acceleration(x, omega, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    """a = −ω × (ω × (x − c)) = ω² r⊥ (outwards from the spin axis), per node (m/s²)."""
    w = np.asarray(omega, dtype=float)
    r = np.asarray(x, dtype=float) - np.asarray(centre, dtype=float)
    return -np.cross(w, np.cross(w, r))


def node_kinetic_energy(model, state: State) -> float:
    """½ Σ m v² + ½ Σ I ω² at the half step (the quantity kinetic damping watches)."""
    return 0.5 * float(np.sum(model.node_mass[:, None] * state.v * state.v)
                       + np.sum(model.node_inertia[:, None] * state.omega * state.omega))


@dataclass
class Relaxation:
    """Outcome of :func:`relax`: steps taken, kinetic-energy resets, the residual (largest
    out-of-balance nodal force over the largest applied one) and whether it converged."""

    steps: int
    resets: int
    residual: float
    converged: bool


# Pseudo-time step of the relaxation, a fraction of the stable step (theory §8.1): at the
# full step a mode near the stability limit (ω Δt → 2, a period of two steps) made the
# kinetic energy peak every other step and the resets stalled the relaxation of the
# default blade with 7.5 and 10 mm elements; at half the step that mode's period is
# about six steps and the blade relaxes with 3 to 10 mm elements.
RELAX_STEP_FRACTION = 0.5


def relax(model, state: State, tol: float = 1e-4, max_steps: int = 200_000,
          check_every: int = 50, step_fraction: float = RELAX_STEP_FRACTION) -> Relaxation:
    """Static equilibrium of ``model`` (its body forces and constraints) by kinetic
    damping, starting from ``state`` (advanced in place; its time and energies are
    those of the pseudo-dynamics and mean nothing).

    Converged when max_n |f_ext − f_int| ≤ tol · max_n |f_ext| over the free degrees of
    freedom (translations), checked every ``check_every`` steps after a reset. The
    pseudo-time step is ``step_fraction`` of the model's stable step.
    """
    ws = Workspace.for_model(model, state)
    free = model.bc_code[:, :3] == 0
    load = np.abs(model.node_mass[:, None] * model.body_accel)[free]
    scale = float(load.max()) if load.size else 0.0
    if not scale > 0.0:
        raise SimulationError("dynamic relaxation needs a body force on a free node")
    ke_prev = 0.0
    resets = 0
    residual = math.inf
    for n in range(1, max_steps + 1):
        step(model, state, ws, dt_cap=step_fraction * model.alpha * ws.dt_min)
        ke = node_kinetic_energy(model, state)
        if ke < ke_prev:
            # past a peak of the kinetic energy: stop every node where the step began.
            # The step already moved x^n → x^{n+1} with v^{n+1/2}; the shell's rate-form
            # resultants (bending, transverse shear, hourglass) take that motion in at
            # the next step, from v^{n+1/2}, so v and x go back together.
            state.x -= state.dt * state.v
            state.v[:] = 0.0
            state.omega[:] = 0.0
            resets += 1
            ke = 0.0
        ke_prev = ke
        if n % check_every == 0:
            out = model.node_mass[:, None] * model.body_accel - state.f_int[:, :3]
            residual = float(np.max(np.abs(out[free]))) / scale
            if residual <= tol:
                return Relaxation(n, resets, residual, True)
    return Relaxation(max_steps, resets, residual, False)


def spin_state(spin_model, model, omega, centre=(0.0, 0.0, 0.0), nodes=None,
               tol: float = 1e-4, max_steps: int = 200_000) -> tuple[State, Relaxation]:
    """The inertial state at t = 0 of a structure turning steadily at ``omega`` (rad/s
    vector) about ``centre``.

    ``spin_model`` is ``model`` with the centrifugal body force
    (:func:`centrifugal_acceleration` at the reference positions) on the spinning nodes
    and the constraints that hold it in the turning frame (e.g. a clamped blade root);
    it is relaxed to equilibrium, and its configuration, element and material state
    are carried into a fresh state of ``model`` with v = ω × (x − c) and spins ω on
    ``nodes`` (default: the nodes that carried the body force).
    """
    from wovenimpact.state import initial_state

    relaxing = initial_state(spin_model)
    info = relax(spin_model, relaxing, tol=tol, max_steps=max_steps)
    if not info.converged:
        from wovenimpact.results.metal_state import max_plastic_strain

        eps_p = float(np.max(max_plastic_strain(spin_model, relaxing), initial=0.0))
        why = (f"the spinning part yields at this rate (plastic strain up to {eps_p:.3g}): "
               "its centrifugal stress passes the material's yield stress, and a plastic "
               "part creeps instead of settling; lower the spin rate" if eps_p > 0.0 else
               "refine the tolerance or check that the spinning part is held (a clamped "
               "root)")
        raise SimulationError(
            f"spin state: dynamic relaxation did not converge in {info.steps} steps "
            f"(residual {info.residual:.2e} > {tol:g}); {why}")
    if nodes is None:
        nodes = np.flatnonzero(np.any(spin_model.body_accel != 0.0, axis=1))
    v = np.zeros((model.n_nodes, 3))
    w = np.zeros((model.n_nodes, 3))
    v[nodes] = np.cross(np.asarray(omega, dtype=float),
                        relaxing.x[nodes] - np.asarray(centre, dtype=float))
    w[nodes] = np.asarray(omega, dtype=float)
    st = initial_state(model, velocity=v, angular_velocity=w)
    st.x[:] = relaxing.x
    st.elem[:] = relaxing.elem
    st.mat[:] = relaxing.mat
    return st, info
