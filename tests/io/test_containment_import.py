"""A containment model from the user's own mesh (issue 11, deliverable 1): an Abaqus file
whose sets ``[mesh.containment]`` names — blade, root, release, fragment, casing layers —
gives the run of the generated case it was written from (setup/compile.containment_sets)."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver import Workspace, step
from wovenimpact.spec.case import case_from_dict
from wovenimpact.spec.fields import read_toml, set_dotted

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "containment"


def generated_doc() -> dict:
    """The 4-ply hybrid example on a coarse 60° sector (10 mm elements): a few thousand
    elements, the blade's spin state and release as in the shipped case."""
    doc = read_toml(EXAMPLES / "hybrid_4.toml", "case file")
    for key, value in (("mesh.element_size", "10 mm"), ("mesh.casing.sector", "60 deg"),
                       ("mesh.casing.centre_angle", "90 deg"), ("run.end_time", "40 us"),
                       ("run.field_interval", "40 us"), ("run.checkpoint_interval", "40 us")):
        set_dotted(doc, key, value)
    for key in ("fine_sector", "coarse_element_size"):
        doc["mesh"]["casing"].pop(key, None)
    doc["boundary"] = [{"nodes": "casing.ends", "type": "clamped"},
                       {"nodes": "casing.cut_edges", "type": "clamped"}]
    return doc


def write_inp(tmp_path: Path, doc: dict) -> tuple[Path, int]:
    """The generated case's mesh as an Abaqus file, with the sets a user would draw:
    one element set per casing layer and per part, the blade's root, release and
    fragment, the casing's ends and cut edges; returns (path, layers)."""
    spec = case_from_dict(doc, source="generated")
    compiled = compile_case(spec, EXAMPLES)
    mesh = compiled.mesh
    layers = sum(1 for k in mesh.node_sets if k.startswith("casing.layer"))
    cell_sets = {f"LAYER{k}": [mesh.elem_sets[f"casing.layer{k}"]] for k in range(layers)}
    cell_sets.update(BLADE=[mesh.elem_sets["blade.blade"]],
                     RELEASE=[mesh.elem_sets["blade.release"]])
    point_sets = {"ROOT": mesh.node_sets["blade.root"],
                  "FRAGMENT": mesh.node_sets["blade.fragment"],
                  "ENDS": mesh.node_sets["casing.ends"],
                  "CUT": mesh.node_sets["casing.cut_edges"]}
    path = tmp_path / "casing_and_blade.inp"
    meshio.write(path, meshio.Mesh(mesh.nodes, [("quad", mesh.quads)], point_sets=point_sets,
                                   cell_sets=cell_sets), file_format="abaqus")
    return path, layers


def imported_doc(doc: dict, path: Path, layers: int) -> dict:
    out = {k: v for k, v in doc.items() if k != "mesh"}
    names = ["shell"] + ["fabric"] * (layers - 1)
    out["mesh"] = {
        "kind": "abaqus", "file": str(path), "warp_direction": "circumferential",
        "sections": {**{f"LAYER{k}": names[k] for k in range(layers)}, "BLADE": "blade"},
        "containment": {"blade": "BLADE", "root": "ROOT", "release": "RELEASE",
                        "fragment": "FRAGMENT",
                        "casing_layers": [f"LAYER{k}" for k in range(layers)]},
    }
    out["contact"] = {**doc.get("contact", {}), "surfaces": "parts"}
    out["boundary"] = [{"nodes": "ENDS", "type": "clamped"}, {"nodes": "CUT", "type": "clamped"}]
    return out


def stepped(doc: dict, steps: int):
    compiled = compile_case(case_from_dict(doc, source="test"), EXAMPLES)
    model, st = compiled.model, compiled.state
    ws = Workspace.for_model(model, st)
    for _ in range(steps):
        step(model, st, ws)
    return model, st


def test_an_imported_casing_and_blade_runs_as_the_generated_case(tmp_path):
    """The generated 4-ply case written to an Abaqus file and read back through
    [mesh.containment]: the same nodes, elements, contact surfaces and containment sets;
    the fragment starts at the same spun speed (1e-9) and after 250 steps (0.35 ms),
    the fragment in the inner shell, the state is the generated run's bit for bit (the
    imported blade's warp is radial, as the generated one's)."""
    doc = generated_doc()
    path, layers = write_inp(tmp_path, doc)
    assert layers == 5
    gen_model, gen = stepped(doc, 0)
    imp_model, imp = stepped(imported_doc(doc, path, layers), 0)
    assert np.array_equal(imp_model.quads, gen_model.quads)
    assert np.array_equal(imp_model.x0, gen_model.x0)
    assert np.array_equal(imp_model.ply, gen_model.ply)
    for name in ("blade.fragment", "blade.root", *(f"casing.layer{k}" for k in range(layers))):
        assert np.array_equal(np.sort(imp_model.node_sets[name]),
                              np.sort(gen_model.node_sets[name])), name
    frag = gen_model.node_sets["blade.fragment"]
    m = gen_model.node_mass[frag]

    def cm_speed(st):
        return np.linalg.norm((m[:, None] * st.v[frag]).sum(axis=0)) / m.sum()

    assert cm_speed(imp) == pytest.approx(cm_speed(gen), rel=1e-9)
    # summary.json's element sizes (results.summary.element_sizes): the case's
    # mesh.element_size (the blade's too, it has none of its own); the imported mesh has no
    # such key, so the median √(element area) of its casing layers and of its blade: the
    # same sizes, within the blade's taper and the ring's curvature
    from wovenimpact.results.summary import element_sizes

    spec = case_from_dict(doc, source="generated")
    assert element_sizes(spec, gen_model) == {"element_size_m": pytest.approx(0.010),
                                              "blade_element_size_m": pytest.approx(0.010)}
    sizes = element_sizes(case_from_dict(imported_doc(doc, path, layers), source="imported"),
                          imp_model)
    assert sizes["element_size_m"] == pytest.approx(0.010, rel=0.05)
    assert sizes["blade_element_size_m"] == pytest.approx(0.010, rel=0.25)
    _, gen = stepped(doc, 250)
    _, imp = stepped(imported_doc(doc, path, layers), 250)
    shell = gen_model.node_sets["casing.layer0"]
    assert np.max(np.abs(gen.x[shell] - gen_model.x0[shell])) > 1e-4  # the fragment struck
    assert np.array_equal(imp.x, gen.x) and np.array_equal(imp.v, gen.v)
    assert np.array_equal(imp.elem, gen.elem) and np.array_equal(imp.mat, gen.mat)


@pytest.mark.parametrize("edit, words", [
    (lambda c: c.update(blade="NOPE"), "mesh.containment.blade: 'NOPE' is not an element set"),
    (lambda c: c.update(release="LAYER0"), "mesh.containment.release: .* not in the blade"),
    (lambda c: c.update(root="FRAGMENT"), "mesh.containment.root: the root nodes must lie"),
    (lambda c: c.update(release="BLADE", fragment="ROOT"),
     "mesh.containment.root: the root nodes must lie"),
    (lambda c: c.update(casing_layers=["LAYER0", "BLADE"]),
     r"mesh.containment.casing_layers\[1\]: set 'BLADE' shares nodes with the blade"),
])
def test_containment_sets_that_do_not_make_a_containment_model_are_refused(tmp_path, edit,
                                                                           words):
    doc = generated_doc()
    path, layers = write_inp(tmp_path, doc)
    imp = imported_doc(doc, path, layers)
    edit(imp["mesh"]["containment"])
    with pytest.raises(InputError, match=words):
        compile_case(case_from_dict(imp, source="test"), EXAMPLES)


def test_a_release_set_that_leaves_the_fragment_joined_is_refused(tmp_path):
    """A release set of half the release row leaves blade elements joining the hub part
    to the fragment: refused, naming one."""
    doc = generated_doc()
    path, layers = write_inp(tmp_path, doc)
    mesh = meshio.read(path, file_format="abaqus")
    rel = mesh.cell_sets["RELEASE"][0]
    mesh.cell_sets["RELEASE"] = [rel[: len(rel) // 2]]
    meshio.write(path, mesh, file_format="abaqus")
    with pytest.raises(InputError, match="release: element .* has nodes on both sides"):
        compile_case(case_from_dict(imported_doc(doc, path, layers), source="test"), EXAMPLES)


def test_spin_without_a_blade_and_a_tilted_axis_are_refused(tmp_path):
    doc = generated_doc()
    path, layers = write_inp(tmp_path, doc)
    imp = imported_doc(doc, path, layers)
    del imp["mesh"]["containment"]
    with pytest.raises(InputError, match="spin: needs a blade to turn"):
        case_from_dict(imp, source="test")
    imp = imported_doc(doc, path, layers)
    imp["mesh"]["axis"] = [1.0, 0.0, 0.0]
    with pytest.raises(InputError, match="mesh.axis: must be the z axis"):
        case_from_dict(imp, source="test")
