"""The crossover cell of thesis §5.2.1 as hexahedra (model/crossover_cell.py, spec/crossover.py):
the geometry of Table 5-1, the yarns meeting without overlap, exact volumes, material axes
along the centrelines, refused geometries, and a case that builds and steps it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.materials.crimp import crimp_amplitude
from wovenimpact.model.crossover_cell import (
    centreline,
    crossover_cell,
    section_area,
    section_profile,
    trimmed_extent,
    yarn_clearance,
)
from wovenimpact.model.solid import SolidSection, solid_part
from wovenimpact.setup.compile import compile_case
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.spec.case import load_case
from wovenimpact.spec.crossover import geometry_from_dict, load_geometry
from wovenimpact.spec.material import load_material

ROOT = Path(__file__).resolve().parents[2]
THESIS = ROOT / "examples" / "crossover" / "thesis_cell.toml"
YARN = ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml"
INCH = 0.0254


def doc(**changes) -> dict:
    d = {"cell": {"name": "cell"},
         "warp": {"thread_count": "27 1/in", "crimp": 0.0421},
         "mesh": {"along": 8, "across": 4, "through": 2}}
    for table, values in changes.items():
        d[table] = {**d.get(table, {}), **values}
    return d


def volumes(cell) -> np.ndarray:
    part = solid_part(cell.mesh.nodes, cell.mesh.hexes,
                      {"yarn": SolidSection(load_material(YARN))},
                      np.zeros(len(cell.mesh.hexes), dtype=np.int64), frames=cell.frames)
    return part.vol0


def test_the_thesis_cell_has_the_dimensions_of_table_5_1():
    """27 threads per inch: a cell 0.9407 mm square (eq. 5.2), 4 h0 = 0.4998 mm thick, the
    yarns 0.2499 mm thick; the centreline of amplitude h0 = 0.12495 mm has the crimp
    0.0422 (Table 5-1's h0 is 0.12 % above eq. 5.5's 0.12480 mm for 0.0421)."""
    cell = crossover_cell(load_geometry(THESIS))
    pitch = INCH / 27
    assert cell.size == pytest.approx((pitch, pitch), rel=1e-12)
    assert cell.thickness == pytest.approx(0.4998e-3, rel=1e-12)
    for y in cell.yarns.values():
        assert (y.amplitude, y.thickness, y.width) == (0.12495e-3, 0.2499e-3, 0.9407e-3)
        assert y.crimp == pytest.approx(0.0421, rel=3e-3)
    assert crimp_amplitude(pitch / 2, 0.0421) == pytest.approx(0.12480e-3, rel=1e-4)
    assert cell.mesh.hexes.shape == (2 * 12 * 8 * 2, 8)
    assert len(cell.mesh.hex_sets["warp"]) == len(cell.mesh.hex_sets["fill"]) == 192


@pytest.mark.parametrize("width, largest", [(None, 1e-15), ("0.9407 mm", 2e-8)])
def test_the_lenticular_yarns_meet_over_the_cell_without_overlapping(width, largest):
    """With t = 2 h0 of the crossing family and W the pitch (the default) the warp's lower
    surface is the fill's upper one: the nodes of the warp's lower surface lie on the fill
    (to round-off) and the clearance is 0. With Table 5-1's width, 0.9407 mm for a pitch
    of 0.94074 mm, they stand off it by at most 16 nm (the rounding), never inside it."""
    cell = crossover_cell(geometry_from_dict(doc(
        warp={"h0": "0.12495 mm", "thickness": "0.2499 mm",
              **({} if width is None else {"width": width})})))
    gap, _ = yarn_clearance(cell.yarns, "lenticular", 0.2)
    assert 0.0 <= gap + 1e-18 and abs(gap) < 1e-15
    f = cell.yarns["fill"]
    x, y, z = cell.mesh.nodes[cell.mesh.node_sets["warp.bottom"]].T
    fill_top = (centreline(f, y, -1.0)[0]
                + 0.5 * f.thickness * section_profile("lenticular", x / (0.5 * f.width)))
    assert -1e-18 <= (z - fill_top).min() and (z - fill_top).max() < largest


def test_volumes_are_exact_and_converge_to_the_lenticular_section():
    """Every element has a positive volume; each yarn's volume is 2ℓ times its polygonal
    section (to round-off), which tends to the trimmed lenticular area as the mesh is
    refined across (the error falls as 1/across²)."""
    errors = []
    for across in (4, 8, 16):
        cell = crossover_cell(geometry_from_dict(doc(mesh={"across": across})))
        v = volumes(cell)
        assert (v > 0.0).all()
        w = cell.yarns["warp"]
        ut = trimmed_extent("lenticular", 0.2)
        u = np.linspace(-ut, ut, across + 1)
        height = w.thickness * section_profile("lenticular", u)
        polygon = np.sum(0.5 * (height[1:] + height[:-1]) * np.diff(u)) * 0.5 * w.width
        warp = v[cell.mesh.hex_sets["warp"]].sum()
        assert warp == pytest.approx(2 * w.half_length * polygon, rel=1e-12)
        exact = 2 * w.half_length * section_area("lenticular", 0.2, w.width, w.thickness)
        errors.append(abs(warp / exact - 1.0))
    assert errors[0] > 3.5 * errors[1] > 3.5 * 3.5 * errors[2]
    assert errors[1] < 0.02


def test_material_axes_follow_the_centrelines():
    """a1 of each element is the tangent of its yarn's centreline at the element's
    mid-station (slopes up to π h0 / 2ℓ, 23°), a2 lies across it in the plane, a3 = a1 × a2
    points up; the rows are orthonormal."""
    cell = crossover_cell(load_geometry(THESIS))
    f = cell.frames
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", f, f), np.broadcast_to(np.eye(3), f.shape),
                               atol=1e-15)
    assert (np.linalg.det(f) > 0).all() and (f[:, 2, 2] > 0.9).all()
    nodes, hexes = cell.mesh.nodes, cell.mesh.hexes
    for name, axis, sign in (("warp", 0, 1.0), ("fill", 1, -1.0)):
        idx = cell.mesh.hex_sets[name]
        s = nodes[hexes[idx]][:, :, axis].mean(axis=1)
        _, slope = centreline(cell.yarns[name], s, sign)
        t = np.zeros((len(idx), 3))
        t[:, axis] = 1.0
        t[:, 2] = slope
        t /= np.linalg.norm(t, axis=1)[:, None]
        np.testing.assert_allclose(f[idx, 0], t, atol=1e-12)
    steepest = math.degrees(math.atan(np.abs(f[:, 0, 2] / np.hypot(f[:, 0, 0], f[:, 0, 1])).max()))
    assert 18.0 < steepest < 23.0


@pytest.mark.parametrize("changes, key", [
    ({"warp": {"thickness": "0.3 mm"}}, "overlap"),
    ({"section": {"shape": "elliptical"}}, "overlap"),
    ({"warp": {"width": "1 mm"}}, "warp.width"),
    ({"warp": {"gap": "1 mm"}}, "warp.gap"),
    ({"section": {"trim": 0}}, "section.trim"),
    ({"mesh": {"along": 1}}, "mesh.along"),
    ({"warp": {"thread_count": "27"}}, "warp.thread_count"),
])
def test_a_geometry_that_cannot_be_built_is_refused_naming_the_key(changes, key):
    with pytest.raises(InputError, match=key):
        crossover_cell(geometry_from_dict(doc(**changes)))


def test_narrower_elliptical_yarns_and_unequal_families_are_built():
    """Elliptical sections as wide as the pitch overlap at the cell's corners, where both
    centrelines pass z = 0 (the case refused above); narrower ones (0.8 mm of pitches
    0.94 and 1.27 mm) clear each other. The families may differ in count and crimp, the
    cell then a rectangle."""
    cell = crossover_cell(geometry_from_dict(doc(
        warp={"thickness": "0.2 mm", "width": "0.8 mm"},
        fill={"thread_count": "20 1/in", "crimp": 0.03, "thickness": "0.2 mm",
              "width": "0.8 mm"},
        section={"shape": "elliptical"})))
    assert cell.size == pytest.approx((INCH / 20, INCH / 27), rel=1e-12)
    gap, _ = yarn_clearance(cell.yarns, "elliptical", 0.2)
    assert gap >= 0.0
    assert (volumes(cell) > 0.0).all()


def test_a_case_builds_the_cell_and_steps_it():
    """``[mesh] kind = "crossover"`` (examples/crossover/cell_at_rest.toml): the thesis's
    cell of the solid yarn, its axes along the yarns, one end of the warp pulled; a few
    steps keep the energy balance."""
    spec, base = load_case(ROOT / "examples" / "crossover" / "cell_at_rest.toml")
    c = compile_case(spec, base)
    model, st = c.model, c.state
    assert model.n_hexes == 384 and model.n_elems == 0
    np.testing.assert_array_equal(model.solid.frame, c.mesh.hex_frames)
    ws = Workspace.for_model(model, st)
    for _ in range(20):
        step(model, st, ws)
    eb = energy_balance(model, st)
    assert eb["internal_work_J"] > 0.0 and eb["error_fraction"] < 1e-3


def repeat_cell(**changes):
    """The 2 × 2 plain-weave repeat of the thesis's geometry (Table 5-1)."""
    d = doc(warp={"h0": "0.12495 mm", "thickness": "0.2499 mm", "width": "0.9407 mm"},
            cell={"repeat": 2}, **changes)
    return crossover_cell(geometry_from_dict(d))


def test_the_repeat_has_four_yarns_of_twice_the_single_cells_volume():
    """The 2 × 2 repeat is 4ℓ square, as thick as the single cell; each of its four yarns
    has 2 × along elements and the volume of two single-cell yarns (4ℓ times the polygonal
    section, to round-off), so the yarns' volume fraction is the single cell's; every
    element has a positive volume and orthonormal right-handed axes."""
    one = crossover_cell(geometry_from_dict(doc(
        warp={"h0": "0.12495 mm", "thickness": "0.2499 mm", "width": "0.9407 mm"})))
    cell = repeat_cell()
    assert cell.repeat == 2 and cell.yarn_names == ("warp0", "warp1", "fill0", "fill1")
    assert cell.size == pytest.approx((2 * one.size[0], 2 * one.size[1]), rel=1e-15)
    assert cell.thickness == pytest.approx(one.thickness, rel=1e-12)
    v, v1 = volumes(cell), volumes(one)
    assert (v > 0.0).all()
    single = v1[one.mesh.hex_sets["warp"]].sum()
    for name in cell.yarn_names:
        assert len(cell.mesh.hex_sets[name]) == 2 * 8 * 4 * 2
        assert v[cell.mesh.hex_sets[name]].sum() == pytest.approx(2 * single, rel=1e-12)
    f = cell.frames
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", f, f),
                               np.broadcast_to(np.eye(3), f.shape), atol=1e-15)
    assert (np.linalg.det(f) > 0).all()


def test_the_repeat_is_a_periodic_plain_weave():
    """Each yarn's x_max (y_max) end face is its x_min (y_min) face shifted by 4ℓ: the
    repeat continues itself. Warp 0 passes over fill 0 and under fill 1, warp 1 the other
    way (the centrelines' heights at the four crossings), and each yarn's material axis
    follows its own centreline's slope."""
    cell = repeat_cell()
    nodes, sets = cell.mesh.nodes, cell.mesh.node_sets
    L = cell.size[0]
    for name in cell.yarn_names:
        axis, (lo, hi) = (0, ("x_min", "x_max")) if name.startswith("warp") else (1, ("y_min", "y_max"))
        shift = np.zeros(3)
        shift[axis] = L
        np.testing.assert_allclose(nodes[sets[f"{name}.{hi}"]], nodes[sets[f"{name}.{lo}"]] + shift,
                                   atol=1e-15)
    ell = 0.25 * L
    mid = {n: nodes[sets[n]] for n in cell.yarn_names}
    for j, name in enumerate(("warp0", "warp1")):
        x = mid[name]
        for i, xc in enumerate((-ell, ell)):
            near = np.abs(x[:, 0] - xc) < 1e-12
            z = x[near, 2].mean()  # the centreline's height at the crossing
            over = (i == j)  # warp0 over fill0, warp1 over fill1
            assert (z > 0.1e-3) if over else (z < -0.1e-3)
    for name in cell.yarn_names:
        idx = cell.mesh.hex_sets[name]
        axis = 0 if name.startswith("warp") else 1
        centre = nodes[cell.mesh.hexes[idx]].mean(axis=1)
        # a1's slope has the sign of dz/ds of the centreline, which changes at the crossings
        slope = cell.frames[idx, 0, 2] / cell.frames[idx, 0, axis]
        sign = {"warp0": 1.0, "warp1": -1.0, "fill0": -1.0, "fill1": 1.0}[name]
        expect = -sign * np.sin(0.5 * np.pi * (centre[:, axis] + ell) / ell)
        assert (np.sign(slope) == np.sign(expect)).all()


def test_the_repeat_yarns_meet_at_every_crossing_without_overlapping():
    """At each of the four crossings the upper yarn's lower surface lies on the lower
    yarn's upper surface (to round-off: the thesis's zero gap), never inside it; the
    parallel yarns stand apart by the pitch less their trimmed width, (1 − u_t) W."""
    cell = repeat_cell()
    nodes, sets = cell.mesh.nodes, cell.mesh.node_sets
    w = cell.yarns["warp"]
    ell = w.half_length
    ut = trimmed_extent("lenticular", 0.2)
    worst = []
    for j, wname in enumerate(("warp0", "warp1")):
        for i, fname in enumerate(("fill0", "fill1")):
            xc, yc = (2 * i - 1) * ell, (2 * j - 1) * ell
            warp_over = i == j
            upper, lower = (wname, fname) if warp_over else (fname, wname)
            p = nodes[sets[f"{upper}.bottom"]]
            # the lower yarn's upper surface at the upper yarn's bottom nodes above it
            if lower.startswith("fill"):
                across, along, sign = p[:, 0] - xc, p[:, 1], (-1.0 if i == 0 else 1.0)
            else:
                across, along, sign = p[:, 1] - yc, p[:, 0], (1.0 if j == 0 else -1.0)
            u = across / (0.5 * w.width)
            above = (np.abs(u) <= ut) & (np.abs(along - (xc if lower.startswith("warp") else yc)) <= ell)
            z_low = (sign * w.amplitude * np.cos(0.5 * np.pi * (along + ell) / ell)
                     + 0.5 * w.thickness * section_profile("lenticular", u))
            gap = p[above, 2] - z_low[above]
            assert above.sum() > 10
            worst.append(gap.min())
            assert gap.max() < 2e-8
    assert min(worst) > -1e-15
    y0 = nodes[sets["warp0"], 1].max()
    y1 = nodes[sets["warp1"], 1].min()
    assert y1 - y0 == pytest.approx((1.0 - ut) * w.width + (2 * ell - w.width), rel=1e-9)


def test_a_repeat_other_than_one_or_two_is_refused_naming_the_key():
    with pytest.raises(InputError, match="cell.repeat"):
        crossover_cell(geometry_from_dict(doc(cell={"repeat": 3})))
