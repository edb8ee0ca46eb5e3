"""From a validated case (:class:`~wovenimpact.spec.case.CaseSpec`) to Model and initial State.

Reads the material files, makes the mesh (structured plate, a block of hexahedra or an
Abaqus ``.inp``), assigns shell and solid sections (:func:`solid_sections`), turns the ``[[boundary]]`` entries into per-DOF constraints and
the ``[[initial_velocity]]`` entries into the velocity field at t = 0. Errors name
the case key that is wrong. Then, in order: the pre-run checks
(:mod:`~wovenimpact.setup.sanity`), and for a spinning blade the spin-up
(:mod:`~wovenimpact.setup.spin_up`) and the checks of the spun blade
(:mod:`~wovenimpact.setup.containment_checks`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.impactor import Impactor
from wovenimpact.model.rigid_plane import RigidPlane
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels.bundles import BodyContact, BodyContactOut, ContactNodes
from wovenimpact.kernels.contact_rigid import rigid_contact_forces
from wovenimpact.model.abaqus import read_inp
from wovenimpact.model.casing import blade_mesh, casing_mesh, circumferential_directions, join
from wovenimpact.model.crossover_cell import crossover_cell
from wovenimpact.model.gmsh import gmsh_hint, read_msh
from wovenimpact.model.lsdyna import read_deck, section_thicknesses
from wovenimpact.model.mesh import Mesh, node_set, plate_mesh
from wovenimpact.model.solid import (
    SolidPart,
    SolidSection,
    block_mesh,
    is_solid_material,
    solid_part,
)
from wovenimpact.model.model import (
    BoundaryConditions,
    Model,
    RigidBody,
    Section,
    ShellContactParams,
    build_model,
)
from wovenimpact.setup.containment_checks import check_containment, check_spin_speed
from wovenimpact.setup.sanity import check_case
from wovenimpact.setup.spin_up import spin_blade
from wovenimpact.spec.case import (
    DOFS,
    LARGE_MESH,
    SYMMETRY_AXIS,
    BlockMeshSpec,
    CaseSpec,
    CrossoverMeshSpec,
    ContainmentMeshSpec,
    ImportedMeshSpec,
    PlateMeshSpec,
)
from wovenimpact.spec.crossover import load_geometry
from wovenimpact.spec.fields import read_toml
from wovenimpact.spec.material import load_material, material_from_dict
from wovenimpact.state import State, initial_state, rigid_rotation_velocity

@dataclass
class CompiledCase:
    """What a run needs: the Model, the State at t = 0 and the mesh it came from."""

    model: Model
    state: State
    mesh: Mesh
    materials: dict


def _material_path(base: Path, name: str, rel: str) -> Path:
    path = (base / rel).resolve()
    if not path.is_file():
        raise InputError(f"materials.{name}: file {rel!r} not found (looked for {path})")
    return path


def _merge(into: dict, new: dict, where: str) -> None:
    """Replace entries of ``into`` by those of ``new``, recursing into tables. A table the
    file does not have is added (an optional one such as ``regularisation``: the material's
    schema then refuses a name it does not know, naming it)."""
    for k, v in new.items():
        if isinstance(v, dict):
            if k not in into:
                into[k] = {}
            if not isinstance(into[k], dict):
                raise InputError(f"{where}.{k}: the material file's {k!r} is a value, not a "
                                 "table")
            _merge(into[k], v, f"{where}.{k}")
        else:
            into[k] = v


def load_case_material(base: Path, name: str, ref):
    """A case's material: its file, with the case's ``set`` values merged in."""
    if isinstance(ref, str):
        return load_material(_material_path(base, name, ref))
    path = _material_path(base, name, ref.file)
    doc = read_toml(path, "material file")
    if ref.set:
        if not isinstance(doc.get("material"), dict):
            raise InputError(f"{path}: no [material] table")
        _merge(doc["material"], copy.deepcopy(ref.set), f"materials.{name}.set")
    return material_from_dict(doc, source=f"{path} (with materials.{name}.set)")


def make_mesh(spec: CaseSpec, base: Path, sections: dict | None = None
              ) -> tuple[Mesh, list[str]]:
    """The mesh and each element's section name; ``mesh.ply`` labels the contact
    surfaces (:func:`contact_surfaces`). A plate with ``ply_sections`` needs the
    sections (their thicknesses stack the plies when no spacing is given)."""
    m = spec.mesh
    if isinstance(m, BlockMeshSpec):  # hexahedra only (solid_sections)
        return block_mesh(m.size, m.elements, m.origin), []
    if isinstance(m, CrossoverMeshSpec):  # the two yarns of a crossover cell
        path = (base / m.file).resolve()
        if not path.is_file():
            raise InputError(f"mesh.file: {m.file!r} not found (looked for {path})")
        return crossover_cell(load_geometry(path)).mesh, []
    if isinstance(m, PlateMeshSpec):
        thick = None
        if m.ply_sections is not None and m.spacing is None:
            thick = [section_thickness(sections[s], f"mesh.ply_sections[{k}]")
                     for k, s in enumerate(m.ply_sections)]
        # touching plies: generated one thickness apart, then stacked by their own
        spacing = m.spacing if thick is None else max(thick)
        mesh = plate_mesh(m.side, m.element_size, plies=m.plies, spacing=spacing or 0.0,
                          quarter=m.quarter, width=m.width)
        if m.ply_sections is None:
            return mesh, [m.section] * mesh.n_elems
        if thick is not None:
            stack_plies(mesh, thick)
        return mesh, [m.ply_sections[k] for k in mesh.ply]
    assert isinstance(m, ImportedMeshSpec)
    path = (base / m.file).resolve()
    if not path.is_file():
        raise InputError(f"mesh.file: {m.file!r} not found (looked for {path})")
    deck = read_deck(path) if m.kind == "lsdyna" else None
    mesh = (deck.mesh if deck is not None
            else read_inp(path) if m.kind == "abaqus" else read_msh(path))
    if mesh.n_elems > LARGE_MESH and not spec.run.allow_large_mesh:  # spec.case.check_mesh_size
        raise InputError(f"mesh.file: {m.file!r} holds {mesh.n_elems:,} elements, more than "
                         f"{LARGE_MESH:,}: a model that takes minutes to build and run on two "
                         "cores (valid: a coarser mesh, or run.allow_large_mesh = true "
                         "(--set run.allow_large_mesh=true) to build it all the same)")
    mesh.nodes *= m.length_unit
    names: list[str | None] = [None] * mesh.n_elems
    shell_sets = [k for k, v in m.sections.items() if v not in spec.solid_sections]
    for elset in shell_sets:
        section = m.sections[elset]
        if elset not in mesh.elem_sets:
            raise InputError(f"mesh.sections: element set {elset!r} is not in {m.file}; "
                             f"sets there: {sorted(mesh.elem_sets)}{gmsh_hint(m.file)}")
        if len(mesh.elem_sets[elset]) == 0:
            raise InputError(f"mesh.sections: element set {elset!r} of {m.file} holds no "
                             f"element, so section {section!r} would be given to nothing "
                             "(valid: a set that holds elements)")
        give_section(names, mesh.elem_sets[elset], section, "element")
    missing = [e for e, s in enumerate(names) if s is None]
    if missing:
        raise InputError(f"mesh.sections: {len(missing)} elements (first: {missing[0]}) are in "
                         "none of the listed element sets; every element needs a section")
    if deck is not None and sections is not None:  # the deck's shell thickness
        sections.update(section_thicknesses(deck, names, sections, m.length_unit, m.file))
    mesh.ply = contact_surfaces(mesh, spec.contact.surfaces, shell_sets)
    return mesh, names  # type: ignore[return-value]


def give_section(names: list, elements, section: str, noun: str) -> None:
    """``names[e] = section`` for each element e of a set of ``mesh.sections``; an element
    already given another section by an earlier set is an InputError (``noun``: "element"
    for shells, "brick" for hexahedra)."""
    for e in elements:
        if names[e] is not None and names[e] != section:
            raise InputError(f"mesh.sections: {noun} {e} is in two sets with different "
                             f"sections ({names[e]!r} and {section!r})")
        names[e] = section


def solid_sections(spec: CaseSpec, materials: dict, mesh: Mesh) -> SolidPart | None:
    """The hexahedra of the mesh with their sections (``[solid_sections.NAME]``): all of
    a block's its ``mesh.section``'s, a crossover cell's warp and fill their
    ``mesh.warp_section`` and ``mesh.fill_section``, an imported mesh's by the element
    sets of ``mesh.sections`` that name a solid section; the material axes the mesh gives
    (a crossover cell's, along its yarns) replace the sections'. None for a mesh without
    hexahedra."""
    sections = {}
    for name, s in spec.solid_sections.items():
        if not is_solid_material(materials[s.material]):
            raise InputError(f"solid_sections.{name}.material: {s.material!r} is not a "
                             "transversely isotropic material (valid: a material file of "
                             "kind = 'transversely_isotropic')")
        sections[name] = SolidSection(materials[s.material], hourglass=s.hourglass,
                                      fibre_direction=s.fibre_direction,
                                      second_direction=s.second_direction)
    m = spec.mesh
    n = mesh.hexes.shape[0]
    if isinstance(m, BlockMeshSpec):
        names: list[str | None] = [m.section] * n
    elif isinstance(m, CrossoverMeshSpec):
        names = [m.warp_section] * n
        for e in mesh.hex_sets["fill"]:
            names[e] = m.fill_section or m.warp_section
    elif isinstance(m, ImportedMeshSpec):
        names = [None] * n
        for elset, section in m.sections.items():
            if section not in sections:
                continue
            if elset not in mesh.hex_sets or not len(mesh.hex_sets[elset]):
                raise InputError(f"mesh.sections: element set {elset!r} of {m.file} holds no "
                                 f"8-node brick (C3D8R, C3D8), so solid section {section!r} "
                                 f"would be given to nothing; sets of bricks there: "
                                 f"{sorted(k for k, v in mesh.hex_sets.items() if len(v))}")
            give_section(names, mesh.hex_sets[elset], section, "brick")
        missing = [e for e, s in enumerate(names) if s is None]
        if missing:
            raise InputError(f"mesh.sections: {len(missing)} 8-node bricks (first: {missing[0]}) "
                             "are in no element set given a solid section "
                             "([solid_sections.NAME]); every element needs a section")
    else:
        return None
    if not n:
        return None
    used = list(dict.fromkeys(names))
    return solid_part(mesh.nodes, mesh.hexes, {k: sections[k] for k in used}, names,
                      frames=mesh.hex_frames, sets=mesh.hex_sets)


def contact_surfaces(mesh: Mesh, how: str, elsets: list[str]) -> np.ndarray:
    """Surface label of each element of an imported mesh (theory §6.3): shells of
    different surfaces meet in the shell–shell contact.

    - ``"parts"``: the connected parts (elements sharing nodes, transitively): the
      layers of an imported pack or casing, each meshed on its own nodes;
    - ``"element_sets"``: the element sets of ``mesh.sections``, in their order;
    - ``"none"``: one surface (no contact unless ``self_contact``).
    """
    ne = mesh.n_elems
    if how == "none":
        return np.zeros(ne, dtype=np.int64)
    if how == "element_sets":
        label = np.full(ne, -1, dtype=np.int64)
        for i, name in enumerate(elsets):
            idx = np.asarray(mesh.elem_sets[name], dtype=np.int64)
            label[idx[label[idx] < 0]] = i
        return label
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    rows = np.repeat(np.arange(ne), 4)
    incidence = coo_matrix((np.ones(4 * ne), (rows, mesh.quads.ravel())),
                           shape=(ne, mesh.n_nodes)).tocsr()
    _, label = connected_components(incidence @ incidence.T, directed=False)
    return label.astype(np.int64)


def erode_at_start(model: Model, state: State, er, key: str) -> None:
    """Erode the elements whose centroid lies within er.radius of the line through
    er.centre along er.cylinder_axis (a hole through the plies); nodes left without a
    live element leave the model, whatever ``run.eroded_nodes`` says (the hole's
    material is not there at t = 0; that option is about material eroded in the run)."""
    from wovenimpact.kernels import shell_layout as SL

    centroid = model.x0[model.quads].mean(axis=1)
    axis = np.asarray(er.cylinder_axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    rel = centroid - np.asarray(er.centre)
    radial = rel - np.outer(rel @ axis, axis)
    hit = np.linalg.norm(radial, axis=1) <= er.radius
    if er.plies is not None:
        hit &= np.isin(model.ply, er.plies)
    if not hit.any():
        raise InputError(f"{key}: no element centroid lies within {er.radius:g} m of the axis "
                         "through centre (and in the given plies)")
    if hit.all():
        raise InputError(f"{key}: radius {er.radius:g} m erodes every element at t = 0 "
                         "(valid: a hole smaller than the plies)")
    state.elem[hit, SL.E_ALIVE] = 0.0
    live = np.zeros(model.n_nodes, dtype=bool)
    live[model.quads[state.elem[:, SL.E_ALIVE] != 0.0].ravel()] = True
    state.node_active[~live] = 0
    state.v[~live] = 0.0
    state.omega[~live] = 0.0


def check_quarter_sideways(im, geometry: Impactor) -> None:
    """A body flying sideways in a quarter model (symmetry on x = 0 and y = 0) must be
    symmetric about both planes: travelling along z, its axis along x or y, its middle
    (the tip plus half its length along the axis) on the z axis."""
    axis = np.asarray(im.axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    middle = np.asarray(im.position, dtype=float) + 0.5 * geometry.total_length * axis
    along = np.count_nonzero(np.abs(axis) > 1e-12) == 1 and abs(axis[2]) == 0.0
    if (not along or abs(im.direction[0]) > 0 or abs(im.direction[1]) > 0
            or abs(middle[0]) > 1e-12 or abs(middle[1]) > 1e-12):
        raise InputError(
            f"impactor: in a quarter model a body flying sideways must be symmetric about "
            f"x = 0 and y = 0: travelling along z (direction {list(im.direction)}), its axis "
            f"along x or y (axis {list(im.axis)}) and its middle, position + length/2 along "
            f"the axis, on the z axis (x = y = 0; it is at "
            f"{np.round(middle[:2] * 1e3, 9).tolist()} mm): e.g. axis = [0, 1, 0] and "
            "position = [0, −length/2, z]")


# the clearance probe of the impactors: a body at rest of unit mass, k = β m / Δt² = 1 N/m
# per node (unit node masses, Δt = 1 s), no dashpot, no friction
PROBE_LAW = {"mass": 1.0, "beta": 1.0, "zeta": 0.0, "mu": 0.0}
PROBE_DT = 1.0


def check_impactor_clearance(model: Model) -> None:
    """Every node must start outside each impactor by at least its contact offset."""
    n = model.n_nodes
    # every node active, at rest, of unit mass: with PROBE_LAW its energy is ½ g²
    nodes = ContactNodes(x=model.x0, v=np.zeros((n, 3)), active=np.ones(n, np.int8),
                         mass=np.ones(n), offset=model.node_offset)
    out = BodyContactOut(force=np.zeros((n, 3)), energy=np.zeros(n), parts=np.zeros((n, 11)),
                         contact_list=np.zeros(n, dtype=np.int64))
    energy = out.energy
    zero = np.zeros(3)
    for b in range(model.body_params.shape[0]):
        p = model.body_params[b]
        st = model.body_state0[b]
        axis = st[RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0]
        tip = st[RB.B_X:RB.B_X + 3] - p[RB.BP_TIP] * axis
        prof = model.body_profiles[b, : int(p[RB.BP_NPTS])]
        body = BodyContact(tip=tip, axis=axis, velocity=zero, spin=zero, centre=zero,
                           prof_z=np.ascontiguousarray(prof[:, 0]),
                           prof_r=np.ascontiguousarray(prof[:, 1]),
                           reach=p[RB.BP_REACH] + float(model.node_offset.max()),
                           **PROBE_LAW)
        rigid_contact_forces(nodes, body, PROBE_DT, out)
        bad = np.flatnonzero(energy > 0.0)
        if bad.size:
            worst = int(bad[np.argmax(energy[bad])])
            depth = np.sqrt(2.0 * energy[worst])
            raise InputError(
                f"impactor.position: the impactor overlaps the structure at t = 0 ({bad.size} "
                f"nodes, node {worst} at {model.x0[worst].tolist()} is {depth * 1e3:.3g} mm "
                "inside its contact offset, half the shell thickness); move the nose tip "
                "further away"
            )


def containment_mesh(m, sections) -> tuple[Mesh, list[str], np.ndarray]:
    """Casing layers and blade of a containment case (model.casing), each element's
    section and warp direction (circumferential on the casing, radial on the blade).
    The casing is meshed at ``mesh.element_size`` (graded to ``coarse_element_size``),
    the blade at ``mesh.blade.element_size`` when given, else at the casing's size."""
    c, b = m.casing, m.blade
    radii, names = [], []
    outer = c.inner_radius
    if c.inner_section is not None:
        t_in = section_thickness(sections[c.inner_section], "mesh.casing.inner_section")
        radii.append(c.inner_radius + 0.5 * t_in)
        names.append(c.inner_section)
        outer = c.inner_radius + t_in
    t_layer = section_thickness(sections[c.layer_section], "mesh.casing.layer_section")
    spacing = t_layer if c.layer_spacing is None else c.layer_spacing
    radii += [outer + (k + 0.5) * spacing for k in range(c.layers)]
    names += [c.layer_section] * c.layers
    if not b.tip_radius < c.inner_radius:
        raise InputError(f"mesh.blade.tip_radius = {b.tip_radius:g} m must be inside the "
                         f"casing (mesh.casing.inner_radius = {c.inner_radius:g} m)")
    try:
        casing = casing_mesh(
            radii, c.length, m.element_size, sector=math.degrees(c.sector),
            centre_angle=math.degrees(c.centre_angle),
            fine_sector=None if c.fine_sector is None else math.degrees(c.fine_sector),
            coarse_size=c.coarse_element_size, offset_layers=c.offset_layers,
            axial_size=c.axial_element_size)
    except InputError as err:
        raise InputError(f"mesh: {err}") from None
    try:  # the blade's own size (mesh.blade.element_size), else the casing's
        blade = blade_mesh(b.root_radius, b.tip_radius, b.crack_radius, b.root_chord,
                           b.tip_chord, m.blade_element_size, angle=math.degrees(b.angle),
                           stagger=math.degrees(b.stagger), twist=math.degrees(b.twist),
                           tip_curve=b.tip_curve, size_key=m.blade_size_key)
    except InputError as err:
        raise InputError(f"mesh.blade: {err}") from None
    # a staggered chord reaches beyond tip_radius at its corners (√(r² + (c/2 sin s)²))
    reach = float(np.hypot(blade.nodes[:, 0], blade.nodes[:, 1]).max())
    if not reach < c.inner_radius:
        raise InputError(f"mesh.blade: the blade's farthest node lies at r = {reach:g} m, not "
                         f"inside the casing (mesh.casing.inner_radius = {c.inner_radius:g} "
                         "m); a staggered chord's corners reach beyond tip_radius: lower "
                         "tip_radius, tip_chord or the stagger, or give a tip_curve")
    mesh = join(casing, blade, prefixes=("casing.", "blade."))
    elem_sections = [names[k] for k in casing.ply] + [b.section] * blade.n_elems
    warp = np.concatenate([circumferential_directions(casing),
                           radial_directions(blade, np.arange(blade.n_elems))])
    return mesh, elem_sections, warp


def radial_directions(mesh: Mesh, elems: np.ndarray) -> np.ndarray:
    """(len(elems), 3) unit radial direction (x, y, 0)/|…| at each element's centroid: a
    blade's warp direction (it lies in the blade; the casing's hoop direction is normal
    to a blade in the plane of the axis). The warp of an isotropic blade only frames its
    element; one rule for generated and imported blades keeps their runs alike."""
    c = mesh.nodes[mesh.quads[elems]].mean(axis=1)
    radial = np.c_[c[:, :2], np.zeros(len(c))]
    return radial / np.linalg.norm(radial, axis=1)[:, None]


def stack_plies(mesh: Mesh, thicknesses: list[float]) -> None:
    """Put ply k's mid-plane at z_k, the plies touching: z_0 = 0, z_k+1 = z_k +
    (t_k + t_k+1)/2 (each section's own thickness; contact offsets are half of it)."""
    z = np.concatenate([[0.0], np.cumsum(0.5 * (np.array(thicknesses[:-1])
                                                + np.array(thicknesses[1:])))])
    for k, zk in enumerate(z):
        mesh.nodes[mesh.node_sets[f"ply{k}"], 2] = zk


def section_thickness(section: Section, key: str) -> float:
    t = section.thickness if section.thickness is not None else getattr(
        section.material, "shell_thickness", None)
    if t is None:
        raise InputError(f"{key}: the section has no thickness")
    return float(t)


def containment_sets(mesh: Mesh, sets, file: str) -> None:
    """Give an imported mesh the set names of a generated containment mesh (theory §8.1):
    ``blade.blade``, ``blade.release`` (element sets), ``blade.root``, ``blade.fragment``
    (node sets) and ``casing.layer{k}`` (node sets, and element sets where the file's set
    is one), from the file's sets that ``[mesh.containment]`` names (``sets``:
    spec.case.ContainmentSetsSpec). Refuses a missing or empty set, a root, release or
    fragment outside the blade, and a release set that does not separate the fragment
    from the hub part (an element outside it with nodes on both sides would keep them
    joined)."""
    key = "mesh.containment"

    def elems(name: str, field: str) -> np.ndarray:
        if name not in mesh.elem_sets:
            raise InputError(f"{key}.{field}: {name!r} is not an element set of {file}; "
                             f"element sets there: {sorted(mesh.elem_sets)}{gmsh_hint(file)}")
        idx = np.unique(np.asarray(mesh.elem_sets[name], dtype=np.int64))
        if idx.size == 0:
            raise InputError(f"{key}.{field}: element set {name!r} of {file} is empty")
        return idx

    def nodes(name: str, field: str) -> np.ndarray:
        if name in mesh.node_sets:
            idx = np.unique(np.asarray(mesh.node_sets[name], dtype=np.int64))
        elif name in mesh.elem_sets:
            idx = np.unique(mesh.quads[np.asarray(mesh.elem_sets[name], dtype=np.int64)])
        else:
            raise InputError(f"{key}.{field}: {name!r} is neither a node set nor an element "
                             f"set of {file}; node sets: {sorted(mesh.node_sets)}{gmsh_hint(file)}")
        if idx.size == 0:
            raise InputError(f"{key}.{field}: set {name!r} of {file} holds no node")
        return idx

    blade = elems(sets.blade, "blade")
    release = elems(sets.release, "release")
    blade_nodes = np.unique(mesh.quads[blade])
    root = nodes(sets.root, "root")
    fragment = nodes(sets.fragment, "fragment")
    for field, idx, within in (("release", release, blade), ("root", root, blade_nodes),
                               ("fragment", fragment, blade_nodes)):
        out = idx[~np.isin(idx, within)]
        if out.size:
            raise InputError(f"{key}.{field}: {out.size} of its entries (first: {out[0]}) are "
                             f"not in the blade {sets.blade!r}")
    kept = blade[~np.isin(blade, release)]
    on_fragment = np.isin(mesh.quads[kept], fragment)
    joined = kept[on_fragment.any(axis=1) & ~on_fragment.all(axis=1)]
    if joined.size:
        raise InputError(f"{key}.release: element {joined[0]} of the blade, not in "
                         f"{sets.release!r}, has nodes on both sides of the fragment "
                         f"{sets.fragment!r}: the release set must hold every element joining "
                         "the fragment to the hub part")
    if np.isin(root, fragment).any():
        raise InputError(f"{key}.root: the root nodes must lie on the hub part, not on the "
                         f"fragment {sets.fragment!r}")
    mesh.elem_sets["blade.blade"] = blade
    mesh.elem_sets["blade.release"] = release
    mesh.node_sets["blade.root"] = root
    mesh.node_sets["blade.fragment"] = fragment
    for k, name in enumerate(sets.casing_layers):
        layer = nodes(name, f"casing_layers[{k}]")
        if np.isin(layer, blade_nodes).any():
            raise InputError(f"{key}.casing_layers[{k}]: set {name!r} shares nodes with the "
                             "blade")
        mesh.node_sets[f"casing.layer{k}"] = layer
        if name in mesh.elem_sets:
            mesh.elem_sets[f"casing.layer{k}"] = np.asarray(mesh.elem_sets[name], dtype=np.int64)


def rigid_planes(spec, mesh) -> list[RigidPlane]:
    """The case's ``[[rigid_plane]]`` tables as RigidPlane (docs/solid.md §6)."""
    planes = []
    for i, p in enumerate(spec.rigid_plane):
        nodes = node_set(mesh, p.nodes, f"rigid_plane[{i}].nodes")
        if nodes.size == 0:
            raise InputError(f"rigid_plane[{i}].nodes: node set {p.nodes!r} holds no node "
                             "(valid: a set that holds nodes)")
        try:
            planes.append(RigidPlane(point=p.point, normal=p.normal, velocity=p.velocity,
                                     nodes=None if p.nodes == "all" else nodes,
                                     beta=p.contact_stiffness, damping=p.contact_damping,
                                     friction=p.friction, name=p.name or f"plane{i}"))
        except InputError as err:
            raise InputError(f"rigid_plane[{i}]: {err}") from None
    return planes


def check_plane_start(model, plane, i: int) -> None:
    """Every node a plane meets must start on its side, at least its contact offset
    from it (a node behind it would be thrown out at t = 0)."""
    meets = np.flatnonzero(plane.node_mask(model.n_nodes))
    side = (model.x0[meets] - np.asarray(plane.point, dtype=float)) @ plane.unit_normal
    behind = meets[side < model.node_offset[meets] - 1e-9 * max(1.0, float(np.ptp(model.x0)))]
    if behind.size:
        raise InputError(
            f"rigid_plane[{i}].point: {behind.size} node(s) it meets start behind the plane "
            f"(node {int(behind[0])} at {model.x0[behind[0]].tolist()} m; valid: every node "
            "of rigid_plane.nodes on the side its normal points to)")


def shell_sections(spec: CaseSpec, materials: dict) -> dict[str, Section]:
    """Builds the case's shell sections (``[sections.NAME]``) on its materials, refusing a
    transversely isotropic material (that is for ``[solid_sections.NAME]``)."""
    for name, s in spec.sections.items():
        if is_solid_material(materials[s.material]):
            raise InputError(f"sections.{name}.material: {s.material!r} is a transversely "
                             "isotropic material, for solid sections (valid: a fabric or "
                             "metal for a shell section, or [solid_sections.NAME])")
    return {
        name: Section(
            material=materials[s.material], thickness=s.thickness,
            bending_modulus=s.bending_modulus, bending_poisson=s.bending_poisson,
            transverse_shear_modulus=s.transverse_shear_modulus, shear_factor=s.shear_factor,
            hourglass=s.hourglass, areal_mass=s.areal_mass, points=s.points,
            membrane=s.membrane,
        )
        for name, s in spec.sections.items()
    }


def case_mesh(spec: CaseSpec, base: Path, sections: dict[str, Section]):
    """Builds the case's mesh, each element's section name and the warp directions (one
    vector, or one per element): a generated containment mesh's, or :func:`make_mesh`'s
    with an imported casing's circumferential warp and an imported blade's radial one
    (its containment sets checked and named, :func:`containment_sets`)."""
    warp = (spec.mesh.warp if isinstance(spec.mesh, ImportedMeshSpec)
            else getattr(spec.mesh, "warp_direction", None))
    if isinstance(spec.mesh, ContainmentMeshSpec):
        return containment_mesh(spec.mesh, sections)
    mesh, elem_sections = make_mesh(spec, base, sections)
    if isinstance(warp, str):  # "circumferential" (an imported casing)
        warp = circumferential_directions(mesh, spec.mesh.axis)
    if getattr(spec.mesh, "containment", None) is not None:
        containment_sets(mesh, spec.mesh.containment, spec.mesh.file)
        # the blade's warp is radial, as a generated blade's (it lies in the plane of
        # the axis, normal to the casing's hoop direction)
        warp = np.array(np.broadcast_to(np.asarray(warp, dtype=float),
                                        (mesh.n_elems, 3)))
        blade = mesh.elem_sets["blade.blade"]
        warp[blade] = radial_directions(mesh, blade)
    return mesh, elem_sections, warp


def boundary_conditions(spec: CaseSpec, mesh: Mesh):
    """Builds the constraints of the case's ``[[boundary]]`` entries and of a spinning
    blade's root: (the :class:`BoundaryConditions`, the spin vector, None without
    ``[spin]``); a boundary on a set that holds no node is refused."""
    bcs = BoundaryConditions(mesh.n_nodes, ramp_time=spec.amplitude.ramp_time)
    for i, b in enumerate(spec.boundary):
        nodes = node_set(mesh, b.nodes, f"boundary[{i}].nodes")
        if nodes.size == 0:
            hint = ("; a full casing ring (mesh.casing.sector = 360 deg) has no cut edges: "
                    "remove this boundary, or model a sector" if b.nodes == "casing.cut_edges"
                    else "")
            raise InputError(f"boundary[{i}].nodes: node set {b.nodes!r} holds no node, so "
                             f"this boundary would constrain nothing (valid: a set that holds "
                             f"nodes{hint})")
        if b.type == "clamped":
            bcs.fix(nodes)
        elif b.type == "pinned":
            bcs.fix(nodes, (0, 1, 2))
        elif b.type in SYMMETRY_AXIS:
            bcs.symmetry(nodes, SYMMETRY_AXIS[b.type])
        else:
            bcs.prescribe(nodes, DOFS.index(b.dof), b.velocity)
    spin = None if spec.spin is None else np.array([0.0, 0.0, spec.spin.rate])
    if spin is not None:  # a containment mesh (spec.case.check_references)
        bcs.rotate(mesh.node_sets["blade.root"], spin)
    return bcs, spin


def impactor_bodies(spec: CaseSpec) -> list[RigidBody]:
    """Builds the rigid body of the case's ``[impactor]`` (none without one): a quarter of
    it in a quarter model, where it must sit on the symmetry axis and travel along z (or
    fly sideways, :func:`check_quarter_sideways`)."""
    bodies = []
    if spec.impactor is not None:
        im = spec.impactor
        try:
            geometry = Impactor(shape=im.shape, radius=im.radius, length=im.length or 0.0,
                                nose=im.nose, nose_length=im.nose_length, fillet=im.fillet,
                                density=im.density)
        except InputError as err:
            raise InputError(f"impactor: {err}") from None
        quarter = isinstance(spec.mesh, PlateMeshSpec) and spec.mesh.quarter
        if quarter and im.axis is None and (
                abs(im.position[0]) > 1e-12 or abs(im.position[1]) > 1e-12
                or abs(im.direction[0]) > 0 or abs(im.direction[1]) > 0):
            raise InputError("impactor: in a quarter model the impactor must sit on the "
                             "symmetry axis (position x = y = 0) and travel along z")
        if quarter and im.axis is not None:
            check_quarter_sideways(im, geometry)
        # a quarter model carries a quarter of the impactor, which moves along its line
        # of travel
        bodies.append(RigidBody(geometry, tip=im.position, direction=im.direction,
                                speed=im.velocity, mass=im.mass, beta=im.contact_stiffness,
                                damping=im.contact_damping, friction=im.friction,
                                fraction=0.25 if quarter else 1.0, axial_only=quarter,
                                axis=im.axis))
    return bodies


def case_model(spec: CaseSpec, mesh: Mesh, sections: dict[str, Section], elem_sections,
               warp, bcs: BoundaryConditions, bodies: list[RigidBody],
               planes: list[RigidPlane], spin, solid: SolidPart | None) -> Model:
    """Builds the case's :class:`Model` (:func:`build_model`) from its mesh, the sections
    its elements use, constraints, impactor, rigid plates and hexahedra, with the body
    force, the contact's and the run's parameters and a spinning blade's release."""
    accel = None if spec.body_force is None else spec.body_force.acceleration
    used = {s: i for i, s in enumerate(dict.fromkeys(elem_sections))}
    return build_model(
        mesh.nodes, mesh.quads, {s: sections[s] for s in used},
        np.array([used[s] for s in elem_sections], dtype=np.int64), bcs=bcs,
        warp_direction=warp, body_accel=accel, alpha=spec.run.alpha,
        erode_dt_fraction=spec.run.erode_dt_fraction, ply=mesh.ply, bodies=bodies,
        node_sets=mesh.node_sets, elem_sets=mesh.elem_sets,
        shell_contact=ShellContactParams(
            enabled=spec.contact.surfaces != "none" or spec.contact.self_contact,
            beta=spec.contact.penalty_scale, damping=spec.contact.damping,
            friction=spec.contact.friction, self_contact=spec.contact.self_contact,
            damping_mode=spec.contact.damping_mode),
        release_elems=mesh.elem_sets.get("blade.release") if spin is not None else None,
        release_time=spec.spin.release_time if spin is not None else math.inf,
        erode_inverted=spec.run.erode_inverted,
        mass_scaling_fraction=spec.run.mass_scaling_fraction,
        max_added_mass_fraction=spec.run.max_added_mass_fraction,
        stable_step=spec.run.stable_step,
        kinematic_fraction=spec.run.kinematic_fraction,
        eroded_nodes=spec.run.eroded_nodes,
        solid=solid,
        rigid_planes=planes,
    )


def initial_velocities(spec: CaseSpec, mesh: Mesh, model: Model):
    """Builds the velocity and angular velocity of every node at t = 0 from the case's
    ``[[initial_velocity]]`` entries (n_nodes, 3 each), zero on the constrained degrees
    of freedom; an entry that would move no node is refused."""
    v = np.zeros((mesh.n_nodes, 3))
    w = np.zeros((mesh.n_nodes, 3))
    for i, iv in enumerate(spec.initial_velocity):
        nodes = node_set(mesh, iv.nodes, f"initial_velocity[{i}].nodes")
        if nodes.size == 0:
            raise InputError(f"initial_velocity[{i}].nodes: node set {iv.nodes!r} holds no "
                             "node, so this velocity would move nothing (valid: a set that "
                             "holds nodes)")
        centre = np.asarray(iv.centre)
        if iv.radius is not None:
            nodes = nodes[np.linalg.norm(mesh.nodes[nodes] - centre, axis=1) <= iv.radius]
            if nodes.size == 0:
                raise InputError(f"initial_velocity[{i}].radius: no node of {iv.nodes!r} lies "
                                 f"within {iv.radius:g} m of {centre.tolist()} (valid: a radius "
                                 "that reaches a node of the set)")
        if iv.velocity is not None:
            v[nodes] += np.asarray(iv.velocity)
        if iv.angular_velocity is not None:
            v[nodes] += rigid_rotation_velocity(mesh.nodes[nodes], iv.angular_velocity, centre)
            w[nodes] += np.asarray(iv.angular_velocity)
    # constrained degrees of freedom start at their constraint
    fixed = model.bc_code[:, :3] == 1
    v[fixed] = 0.0
    w[model.bc_code[:, 3:] == 1] = 0.0
    return v, w


def compile_case(spec: CaseSpec, base: Path) -> CompiledCase:
    """Build the Model and the State at t = 0 of a case (paths relative to ``base``)."""
    base = Path(base)
    materials = {n: load_case_material(base, n, ref) for n, ref in spec.materials.items()}
    sections = shell_sections(spec, materials)
    mesh, elem_sections, warp = case_mesh(spec, base, sections)
    bcs, spin = boundary_conditions(spec, mesh)
    bodies = impactor_bodies(spec)
    planes = rigid_planes(spec, mesh)
    solid = solid_sections(spec, materials, mesh)
    model = case_model(spec, mesh, sections, elem_sections, warp, bcs, bodies, planes, spin,
                       solid)
    for i, plane in enumerate(planes):
        check_plane_start(model, plane, i)
    v, w = initial_velocities(spec, mesh, model)
    check_impactor_clearance(model)
    state = initial_state(model, velocity=v, angular_velocity=w)
    dt = check_case(spec, model, state, mesh, sections)  # setup.sanity: before the spin-up
    if spin is not None:
        check_spin_speed(spec, model, mesh, dt)
        blade = {elem_sections[e] for e in mesh.elem_sets["blade.blade"]}
        if len(blade) != 1:
            raise InputError(f"mesh.containment.blade: the blade's elements have sections "
                             f"{sorted(blade)}; its spin state needs one section")
        spin_blade(model, state, mesh, sections[blade.pop()], spin,
                   spec.spin.relaxation_tolerance, warp)
        check_containment(spec, model, state, mesh)  # on the spun blade
    for i, er in enumerate(spec.initial_erosion):
        erode_at_start(model, state, er, f"initial_erosion[{i}]")
    return CompiledCase(model=model, state=state, mesh=mesh, materials=materials)
