"""A minimal explicit driver for the hexahedron kernels alone (tests only: the kernels
checked without the solver's Model / State / step, which tests/verification/
test_solid_solver.py runs them through).

Central differences with the lumped mass ρ0 V0 / 8 per corner (the mass the element's
stable step assumes): v^{n+1/2} = v^{n−1/2} + Δt M⁻¹ (f_ext − f_int^n − c M v^{n−1/2}),
x^{n+1} = x^n + Δt v^{n+1/2}, prescribed nodes moved at their given velocity. The kinetic
energy at t^n is the leapfrog form ½ v^{n−1/2}·M v^{n+1/2} (kernels/integrate.py), which
with the elements' trapezoidal energies conserves a linear system's energy at constant Δt.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wovenimpact.kernels import solid_layout as L
from wovenimpact.kernels.bundles import HexMesh, HexResults, HexTables, Motion
from wovenimpact.kernels.hex8 import (
    gather_hex_forces,
    internal_force_for_hexes,
    reference_geometry_for_hexes,
)
from wovenimpact.materials.transverse_isotropic import (
    TransverseIsotropicParameters,
    initial_state,
)

# thesis Table 5-2: the yarn of the 3-D crossover (E11 96 GPa, E22 = E33 = G = 3.28 GPa,
# ν = 0, 1.44 g/cm³)
THESIS_YARN = TransverseIsotropicParameters(
    e11=96e9, e22=3.28e9, g12=3.28e9, g23=3.28e9, nu12=0.0, nu23=0.0, density=1440.0,
    name="thesis_yarn")

# parent coordinates of the corners (solid_layout node order)
PARENT = np.array([L.HEX_XI, L.HEX_ETA, L.HEX_ZETA]).T


def node_corner_map(hexes: np.ndarray, n_nodes: int):
    """CSR map node → (element, corner), elements in increasing order per node."""
    flat = hexes.ravel()
    order = np.argsort(flat, kind="stable")
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(flat, minlength=n_nodes), out=ptr[1:])
    return ptr, (order // 8).astype(np.int64), (order % 8).astype(np.int64)


def box_mesh(nx: int, ny: int, nz: int, lx: float, ly: float, lz: float):
    """Nodes and hexahedra of an nx × ny × nz grid on [0, lx] × [0, ly] × [0, lz]."""
    xs, ys, zs = (np.linspace(0.0, lx, nx + 1), np.linspace(0.0, ly, ny + 1),
                  np.linspace(0.0, lz, nz + 1))
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)

    def nid(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    hexes = [[nid(i + int(p[0] > 0), j + int(p[1] > 0), k + int(p[2] > 0)) for p in PARENT]
             for i in range(nx) for j in range(ny) for k in range(nz)]
    return nodes, np.array(hexes, dtype=np.int64)


@dataclass
class HexModel:
    """Arrays of a hexahedron mesh ready for the kernels, and a central-difference loop."""

    nodes: np.ndarray
    hexes: np.ndarray
    params: TransverseIsotropicParameters
    frames: np.ndarray
    hourglass: float = 0.05  # r
    mesh: HexMesh = field(init=False)
    mass: np.ndarray = field(init=False)
    node_map: tuple = field(init=False)

    def __post_init__(self) -> None:
        ne = len(self.hexes)
        self.hexes = np.ascontiguousarray(self.hexes, dtype=np.int64)
        frames = np.broadcast_to(np.asarray(self.frames, dtype=float).reshape(-1, 3, 3),
                                 (ne, 3, 3))
        ref_grad = np.zeros((ne, 3, 8))
        vol0 = np.zeros(ne)
        k = np.zeros(ne)
        scale = np.full(ne, self.hourglass * self.params.hourglass_modulus)
        reference_geometry_for_hexes(self.hexes, np.ascontiguousarray(self.nodes, dtype=float),
                                     scale, ref_grad, vol0, k)
        assert (vol0 > 0.0).all()
        self.mesh = HexMesh(hexes=self.hexes, elem_mat=np.zeros(ne, dtype=np.int64),
                            mat_params=self.params.to_array()[None, :],
                            frame=np.ascontiguousarray(frames), ref_grad=ref_grad, vol0=vol0,
                            hg_stiffness=k)
        self.mass = np.zeros(len(self.nodes))
        np.add.at(self.mass, self.hexes.ravel(), np.repeat(self.params.density * vol0 / 8.0, 8))
        self.node_map = node_corner_map(self.hexes, len(self.nodes))

    def state(self) -> np.ndarray:
        return initial_state(len(self.hexes))

    def forces(self, x, v, dt, el_in, el_out):
        """Internal nodal forces at x (v the half-step velocity that led there over dt);
        returns (f_int (n_nodes, 3), dt_min) and writes el_out."""
        ne = len(self.hexes)
        res = HexResults(blocks=np.zeros((ne, 8, 3)), status=np.zeros(ne, dtype=np.int32))
        motion = Motion(x=x, v=v, omega=v)
        n_failed, dt_min = internal_force_for_hexes(self.mesh, motion, float(dt),
                                                    HexTables(el_in, el_out), res)
        assert n_failed == 0, res.status
        f = np.zeros_like(x)
        gather_hex_forces(*self.node_map, res.blocks, f)
        return f, dt_min, res.blocks

    def run(self, x, v, dt, n_steps, fixed=None, damping=0.0, every=1, record=None,
            path_free=False):
        """n_steps of central differences from x^0 and v^{−1/2} (fixed: bool (n_nodes, 3),
        those degrees of freedom keep their velocity). Returns (x, v, state, history,
        records): history rows (t, kinetic, strain, hourglass) at every ``every`` step and,
        with ``record`` a callable of (x, v), its values there.

        ``path_free``: every force is that of the virgin elements taken in one increment
        from the reference positions to x (a function of x alone: no path dependence of
        the rate forms), for relaxing to the equilibrium of the element equations."""
        x = np.array(x, dtype=float)
        v = np.array(v, dtype=float)
        el_in, el_out = self.state(), self.state()
        m = self.mass[:, None]
        hist, rec = [], []
        v_prev = v.copy()
        for n in range(n_steps + 1):
            # x^n reached from x^{n−1} by v^{n−1/2} (the elements' increments); the first
            # call takes the whole way from the reference positions
            if n == 0 or path_free:
                f, _, _ = self.forces(x, x - self.nodes, 1.0, self.state(), el_out)
            else:
                f, _, _ = self.forces(x, v_prev, dt, el_in, el_out)
            v_new = v_prev + dt * (-f / m - damping * v_prev)
            if fixed is not None:
                v_new[fixed] = v_prev[fixed]
            if n % every == 0:
                ke = 0.5 * float(np.sum(m * v_prev * v_new))
                hist.append((n * dt, ke, float(el_out[:, L.H_W].sum()),
                             float(el_out[:, L.H_W_HG].sum())))
                if record is not None:
                    rec.append(record(x, v_new))
            el_in, el_out = el_out, el_in
            x = x + dt * v_new
            v_prev = v_new
        return x, v_prev, el_in, np.array(hist), rec
