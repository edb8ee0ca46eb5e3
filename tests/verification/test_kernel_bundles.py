"""The two widest kernels take named bundles of arrays (kernels.bundles, issue 13).

- every output field of a bundle is written by its kernel (Numba may drop writes to an
  array unpacked badly from a tuple argument as dead code: kernels/bundles.py);
- the Model's bundles are built once and hold the Model's own arrays;
- the per-step bundles follow the State's current arrays (a State given new arrays
  between steps runs exactly like one that was not).
"""

from __future__ import annotations

import numpy as np

from tests.verification.meshes import elastic, rect_grid
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.bundles import NodeForces
from wovenimpact.kernels.gather import gather_nodal_forces
from wovenimpact.kernels.integrate import gather_and_update
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.solver import Workspace, step
from wovenimpact.solver.explicit import node_motion, shell_forces
from wovenimpact.state import initial_state


def two_material_plate(kevlar):
    """A 4 × 3 plate, fabric (full membrane, material points) and elastic metal
    (reduced) columns side by side, one edge fixed and one corner driven."""
    nodes, quads = rect_grid(4, 3, 0.02, 0.015)
    sections = {
        "fabric": Section(kevlar, transverse_shear_modulus=3.28e9, bending_modulus=1e9),
        "metal": Section(elastic(), thickness=5e-4),
    }
    elem_section = np.where(np.arange(len(quads)) < 6, "fabric", "metal")
    bc = BoundaryConditions(len(nodes), ramp_time=1e-6)
    bc.fix(np.flatnonzero(nodes[:, 0] == 0.0))
    bc.prescribe([len(nodes) - 1], 2, 5.0)
    model = build_model(nodes, quads, sections, elem_section, bcs=bc)
    rng = np.random.default_rng(1)
    st = initial_state(model, velocity=rng.uniform(-1.0, 1.0, (len(nodes), 3)),
                       angular_velocity=rng.uniform(-50.0, 50.0, (len(nodes), 3)))
    return model, st


def test_the_kernels_write_every_output_field(kevlar):
    model, st = two_material_plate(kevlar)
    ws = Workspace.for_model(model, st)
    for _ in range(3):
        step(model, st, ws)

    out = ws.element_out
    for a in (ws.elem, ws.mat, out.blocks):
        a.fill(np.nan)
    out.alive.fill(255)
    out.status.fill(-7)
    out.eroded_now.fill(-7)
    shell_forces(model, st, ws)
    assert np.isfinite(ws.elem).all() and np.isfinite(ws.mat).all()
    assert np.isfinite(out.blocks).all() and np.any(out.blocks != 0.0)
    np.testing.assert_array_equal(out.alive, (ws.elem[:, SL.E_ALIVE] != 0.0).astype(np.uint8))
    assert np.all(out.status == SL.EL_OK) and np.all(out.eroded_now == 0)

    for a in (ws.f_int, ws.f_ext, *ws.node_energy):
        a.fill(np.nan)
    forces = NodeForces(f_int=ws.f_int, f_ext=ws.f_ext, f_int_old=st.f_int,
                        f_ext_old=st.f_ext, f_con=ws.contact.f_con)
    n_bad = gather_and_update(model.node_arrays, out, node_motion(st), forces,
                              ws.node_energy, amplitude=1.0, dt_old=st.dt, dt_new=st.dt)
    assert n_bad == 0
    for a in (ws.f_int, ws.f_ext, *ws.node_energy):
        assert np.isfinite(a).all()
    assert np.any(ws.node_energy.ke != 0.0) and np.any(ws.node_energy.w_int != 0.0)
    # the fused gather is the gather alone
    f_gather = np.empty_like(ws.f_int)
    gather_nodal_forces(model.node_ptr, model.node_elem, model.node_corner, out.blocks,
                        out.alive, f_gather, ws.live)
    np.testing.assert_array_equal(ws.f_int, f_gather)


def test_model_bundles_are_built_once_of_the_models_arrays(kevlar):
    model, _ = two_material_plate(kevlar)
    assert model.node_arrays is model.node_arrays
    assert model.shell_arrays is model.shell_arrays
    assert model.node_arrays.mass is model.node_mass
    assert model.node_arrays.node_ptr is model.node_ptr
    assert model.shell_arrays.mat_params is model.mat_params
    assert model.shell_arrays.point_width == model.point_width


def test_a_state_given_new_arrays_between_steps_runs_the_same(kevlar):
    """The per-step bundles are assembled from the State's arrays at each call, so
    replacing them (as tests and scripts do: ``st.x = …``) is seen by the kernels."""
    model, st_a = two_material_plate(kevlar)
    st_b = st_a.copy()
    ws_a, ws_b = Workspace.for_model(model, st_a), Workspace.for_model(model, st_b)
    for _ in range(5):
        step(model, st_a, ws_a)
        step(model, st_b, ws_b)
        st_b.x, st_b.v, st_b.omega = st_b.x.copy(), st_b.v.copy(), st_b.omega.copy()
        st_b.elem, st_b.mat = st_b.elem.copy(), st_b.mat.copy()
    for name in ("x", "v", "omega", "elem", "mat", "f_int", "f_ext", "energy"):
        np.testing.assert_array_equal(getattr(st_a, name), getattr(st_b, name), err_msg=name)
