"""In-plane shear of the crossover cell by a pin-jointed frame (calibration/cell_shear.py,
docs/solid.md §6.7): the frame's kinematics, a driver that does no work on yarns that do
not touch, the test on a coarse 2 × 2 repeat, the locking rules on curves with a known
answer and the shell's trellis law beside it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.calibration.cell_shear import (
    crossing_misfit,
    driven_ends,
    end_motion,
    end_motion_rate,
    frame_gradient,
    locking_angle,
    meshed_trellis_angles,
    meshed_width,
    shear_cell,
    smooth_ramp_integral,
    stiffening_angle,
    trellis_angles,
    trellis_law,
)
from wovenimpact.calibration.crossover_cell import element_volumes
from wovenimpact.errors import InputError
from wovenimpact.kernels.integrate import smooth_step
from wovenimpact.model.crossover_cell import crossover_cell
from wovenimpact.model.model import ShellContactParams
from wovenimpact.spec.crossover import geometry_from_dict
from wovenimpact.spec.material import load_material

ROOT = Path(__file__).resolve().parents[2]
YARN = load_material(ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml")
FABRIC = load_material(ROOT / "examples" / "materials" / "kevlar_thesis.toml")


def repeat_doc(along=6, across=4, through=2, repeat=2) -> dict:
    """The thesis's geometry (Table 5-1) as the 2 × 2 repeat, coarse."""
    return {"cell": {"name": "repeat", "repeat": repeat},
            "warp": {"thread_count": "27 1/in", "crimp": 0.0421, "width": "0.9407 mm",
                     "thickness": "0.2499 mm", "h0": "0.12495 mm"},
            "mesh": {"along": along, "across": across, "through": through}}


def test_the_frame_shears_the_net_and_turns_each_yarn_rigidly():
    """F(γ) keeps both families' lengths and closes their angle to 90° − γ; a yarn's end
    nodes keep their distances (a rigid motion), its axis point c goes to F c and its
    direction turns by ±γ/2, so parallel warps end pitch × cos γ apart; ∂x/∂γ is the
    derivative of x(γ) (central differences)."""
    g = math.radians(25.0)
    F = frame_gradient(g)
    ex, ey = F @ [1.0, 0.0], F @ [0.0, 1.0]
    assert np.linalg.norm(ex) == pytest.approx(1.0) and np.linalg.norm(ey) == pytest.approx(1.0)
    assert math.degrees(math.acos(ex @ ey)) == pytest.approx(90.0 - 25.0, rel=1e-12)
    cell = crossover_cell(geometry_from_dict(repeat_doc()))
    ends = driven_ends(cell)
    assert [e.name for e in ends] == ["warp0", "warp1", "fill0", "fill1"]
    pitch = 0.5 * cell.size[1]
    np.testing.assert_allclose(ends[0].centre, [0.0, -0.5 * pitch], atol=1e-15)
    for e in ends:
        x = end_motion(g, e.X, e.centre, e.turn)
        d0 = np.linalg.norm(e.X[:, None] - e.X[None], axis=-1)
        d = np.linalg.norm(x[:, None] - x[None], axis=-1)
        np.testing.assert_allclose(d, d0, atol=1e-15)
        np.testing.assert_allclose(end_motion(g, e.centre[None], e.centre, e.turn)[0],
                                   F @ e.centre, atol=1e-15)
        h = 1e-6
        fd = (end_motion(g + h, e.X, e.centre, e.turn)
              - end_motion(g - h, e.X, e.centre, e.turn)) / (2 * h)
        np.testing.assert_allclose(end_motion_rate(g, e.X, e.centre, e.turn), fd, atol=1e-12)
    axis0 = F @ ends[0].centre
    axis1 = F @ ends[1].centre
    normal = np.array([-math.sin(0.5 * g), math.cos(0.5 * g)])  # across the turned warps
    assert (axis1 - axis0) @ normal == pytest.approx(pitch * math.cos(g), rel=1e-12)


def test_the_ramp_integral_is_the_integral_of_the_smooth_step():
    """Its derivative (central differences) is the smooth step A(t) everywhere, and it
    starts at 0: γ(t) = γ̇ ∫ A is the angle of a rate ramped in as the other tests' speeds."""
    ramp = 5e-6
    h = 1e-11
    t = np.linspace(h, 8e-6, 801)
    a = np.array([smooth_step(s, ramp) for s in t])
    rate = np.array([(smooth_ramp_integral(s + h, ramp) - smooth_ramp_integral(s - h, ramp))
                     / (2 * h) for s in t])
    np.testing.assert_allclose(rate, a, atol=1e-6)
    assert smooth_ramp_integral(0.0, ramp) == 0.0
    assert smooth_ramp_integral(8e-6, ramp) == pytest.approx(0.5 * ramp + 3e-6, rel=1e-14)


def test_yarns_that_do_not_touch_are_moved_rigidly_by_the_frame():
    """With the contact off, the frame's end motions are rigid motions of each yarn: to
    10° the internal work stays below 1e-3 of what the same angle would store if the
    yarns were sheared in their plane (½ G12 γ² V, the affine frame), and the energy
    balance closes."""
    r = shear_cell(geometry_from_dict(repeat_doc(along=4, across=2, through=1)), YARN,
                   angle=math.radians(10.0), rate=1e4, samples=10,
                   contact=ShellContactParams(enabled=False))
    assert r.stopped == "angle" and r.gamma[-1] >= math.radians(10.0)
    cell = crossover_cell(geometry_from_dict(repeat_doc(along=4, across=2, through=1)))
    volume = float(element_volumes(cell).sum())
    affine = 0.5 * YARN.g12 * r.gamma[-1] ** 2 * volume
    internal = r.work[-1]  # the frame's work: internal work plus kinetic energy
    assert abs(internal) < 1e-3 * affine
    assert r.energy_error < 1e-3


@pytest.fixture(scope="module")
def coarse_run():
    """The coarse repeat (6 × 4 × 2 elements per crossing and yarn) to 4° at 1100 rad/s,
    the yarns' end faces clamped (``ends = "held"``): slow enough to be quasi-static over
    the run's second half (the kinetic energy over the internal work falls as 1/γ²)."""
    return shear_cell(geometry_from_dict(repeat_doc()), YARN, angle=math.radians(4.0),
                      rate=1.1e3, samples=8)


SHORT, FAST = math.radians(2.0), 3e3  # the end conditions' comparison: angle, rate


@pytest.fixture(scope="module")
def hinged_run():
    """The same repeat to 2° at 3000 rad/s with ``ends = "hinged"`` (τ within 5 % of
    2000 rad/s on this cell; not asserted quasi-static, only compared with the held run)."""
    return shear_cell(geometry_from_dict(repeat_doc()), YARN, angle=SHORT, rate=FAST,
                      samples=4, ends="hinged")


def held_at(run, gamma, values):
    """The clamped run's ``values`` at the angle ``gamma`` (linear between its samples)."""
    return float(np.interp(gamma, run.gamma, values))


def test_the_coarse_repeat_resists_shear_through_its_crossings(coarse_run):
    """The frame's moment rises with every sample after the ramp (the crossings' yarns
    pressed into each other as they turn: a monotonic τ(γ)), the work the frame puts in
    is positive and the run is quasi-static: kinetic energy below 1 % of the internal
    work over the second half, energy error below 1 %, hourglass energy below 10 %. The
    parallel yarns, 0.12 mm apart as meshed, do not touch at 4°; the crossings carry."""
    r = coarse_run
    assert r.ends == "held"
    assert r.stopped == "angle" and r.repeat == 2 and r.elements == 4 * 12 * 4 * 2
    after = r.gamma > math.radians(1.0)
    assert (np.diff(r.stress[after]) > 0.0).all()
    assert r.stress[-1] > 0.0 and r.work[-1] > 0.0
    assert r.kinetic_fraction < 0.01
    assert r.energy_error < 0.01
    assert r.hourglass_fraction < 0.10
    assert np.all(r.parallel_force == 0.0)
    assert r.crossing_force[-1] > 0.0 and r.crossing_contact[-1] >= r.crossing_force[-1]
    # the definitions: τ = T / (A0 t), N_s = T / A0
    np.testing.assert_allclose(r.stress * r.area * r.thickness, r.moment, rtol=1e-12)
    np.testing.assert_allclose(r.resultant * r.area, r.moment, rtol=1e-12)


def test_hinged_ends_let_the_crossings_open_and_the_cell_thicken(coarse_run, hinged_run):
    """With each end face driven and held in z along its mid-height line only, the yarns'
    slopes at their inflection points are free: the crossings open instead of being
    crushed only, so the cell grows thicker as it is sheared — more than twice as much as
    with clamped ends at the same angle — and the crossings press each other less and the
    frame's moment is lower. The frame still does positive work, the run does not give way
    and its energy balance closes; the parallel yarns do not touch."""
    h, r = hinged_run, coarse_run
    assert h.stopped == "angle" and h.ends == "hinged"
    g = h.gamma[-1]
    after = h.gamma > math.radians(1.0)
    assert (np.diff(h.thickening[after]) > 0.0).all()
    assert h.thickening[-1] > 2.0 * max(held_at(r, g, r.thickening), 0.0)
    assert h.crossing_contact[-1] < held_at(r, g, r.crossing_contact)
    assert 0.0 < h.stress[-1] < held_at(r, g, r.stress)
    assert h.work[-1] > 0.0
    assert h.energy_error < 1e-3
    assert np.all(h.parallel_force == 0.0)


def test_free_z_ends_let_each_yarn_climb_through_the_cell(coarse_run):
    """With the end faces free in z (driven in x, y only) nothing outside acts along z:
    the cell's centre of mass keeps its height to round-off. The crossings' misfit then
    goes into the yarns tilting — each yarn's two end faces move apart vertically, one up
    and one down, each by about as much as the cell thickens — which a periodic fabric
    cannot do (a yarn's two ends are the same inflection point, one repeat apart). The
    crossings then press each other far less (the sum of their contact forces below half
    the clamped cell's) and the frame's moment is far below the clamped cell's at the same
    angle."""
    f = shear_cell(geometry_from_dict(repeat_doc()), YARN, angle=0.75 * SHORT, rate=FAST,
                   samples=4,
                   ends="free_z")
    assert f.stopped == "angle" and f.ends == "free_z"
    t = crossover_cell(geometry_from_dict(repeat_doc())).yarns["warp"].thickness
    assert np.abs(f.centre_z).max() < 1e-9 * t
    rise = f.end_z[-1]  # yarns × (first face, second face)
    assert np.all(rise[:, 0] * rise[:, 1] < 0.0)  # the two ends move opposite ways
    assert f.thickening[-1] > 0.0
    np.testing.assert_allclose(np.abs(rise), f.thickening[-1], rtol=0.25)
    g = f.gamma[-1]
    assert f.stress[-1] < 0.5 * held_at(coarse_run, g, coarse_run.stress)
    assert f.crossing_contact[-1] < 0.5 * held_at(coarse_run, g, coarse_run.crossing_contact)


def test_the_hinge_is_each_end_face_s_mid_height_line():
    """``ends = "hinged"`` drives, on each end face, the nodes at mid-height of their
    column: one line across the yarn (across + 1 nodes) at the inflection point's height
    z = 0; a mesh with an odd number of elements through has no such line and is refused,
    as is an unknown ``ends``."""
    cell = crossover_cell(geometry_from_dict(repeat_doc()))
    ends = driven_ends(cell, "hinged")
    for e, full in zip(ends, driven_ends(cell)):
        assert len(e.nodes) == 2 * (4 + 1)
        assert np.abs(cell.mesh.nodes[e.nodes, 2]).max() < 1e-15
        np.testing.assert_allclose(e.centre, full.centre, atol=1e-15)
    odd = crossover_cell(geometry_from_dict(repeat_doc(through=3)))
    with pytest.raises(InputError, match="through"):
        driven_ends(odd, "hinged")
    with pytest.raises(InputError, match="ends"):
        driven_ends(cell, "periodic")


def test_the_shear_test_refuses_bad_input_naming_it():
    spec = geometry_from_dict(repeat_doc())
    for kwargs, key in (({"angle": 2.0}, "angle"), ({"rate": 0.0}, "rate"),
                        ({"samples": 2}, "samples"), ({"max_kinetic": 0.0}, "max_kinetic"),
                        ({"ends": "free"}, "ends")):
        with pytest.raises(InputError, match=key):
            shear_cell(spec, YARN, **kwargs)


def bilinear(gamma, g1, g2, lock):
    return np.where(gamma < lock, g1 * gamma, g1 * lock + g2 * (gamma - lock))


def test_the_locking_rules_find_the_corner_of_a_bilinear_curve():
    """τ = G1 γ up to γL, then slope G2: the tangents' intersection is γL (both windows
    within a branch), the tangent reaches 10 × G1 within a sample of γL; a straight
    line (or a mild stiffening) has no locking angle."""
    gamma = np.linspace(0.0, math.radians(40.0), 401)
    lock = math.radians(25.0)
    tau = bilinear(gamma, 1e6, 50e6, lock)
    assert locking_angle(gamma, tau) == pytest.approx(lock, rel=1e-9)
    assert stiffening_angle(gamma, tau) == pytest.approx(lock, abs=gamma[1])  # within a sample
    assert math.isnan(locking_angle(gamma, 3e6 * gamma))
    assert math.isnan(locking_angle(gamma, bilinear(gamma, 1e6, 2e6, lock)))
    assert math.isnan(stiffening_angle(gamma, 3e6 * gamma))


def test_the_trellis_law_and_its_locking_angles_are_the_shells():
    """trellis_angles gives the shell's γ1, γ2 (materials.fabric, eqs. 3.13–3.14) for the
    reference fabric — 0.53° and 49.46° — and 29.3° / 55.5° for the cell's meshed width
    (the lenticular section trimmed at a fifth of its thickness is 0.872 of the pitch
    wide); trellis_law is G1 γ below γ1 and G2 γ beyond γ2."""
    f = FABRIC
    pitch = 2.0 * f.fill.half_length
    g1, g2 = trellis_angles(f.warp.width, pitch, f.shear_c_max)
    assert (g1, g2) == pytest.approx(f.locking_angles, rel=1e-12)
    assert (math.degrees(g1), math.degrees(g2)) == pytest.approx((0.53, 49.46), abs=0.01)
    cell = crossover_cell(geometry_from_dict(repeat_doc()))
    m1, m2 = trellis_angles(meshed_width(cell), 0.5 * cell.size[1], f.shear_c_max)
    assert (math.degrees(m1), math.degrees(m2)) == pytest.approx((29.3, 55.5), abs=0.1)
    # the same from the spec, on the repeat and on the single crossover (pitch = side / repeat)
    for doc in (repeat_doc(), repeat_doc(repeat=1)):
        assert meshed_trellis_angles(geometry_from_dict(doc), f.shear_c_max) == pytest.approx(
            (m1, m2), rel=1e-12)
    gam = np.array([0.5 * g1, 1.2 * g2])
    tau = trellis_law(gam, f.shear_g1, f.shear_g2, g1, g2)
    assert tau == pytest.approx([f.shear_g1 * gam[0], f.shear_g2 * gam[1]], rel=1e-12)


def test_turning_the_crossing_yarns_rigidly_makes_them_overlap():
    """The thesis's yarns meet without overlapping (misfit 0 at γ = 0, to round-off); turned
    rigidly by ±γ/2 they overlap by a depth that grows about in proportion to γ (the
    surfaces' slopes, up to 23°, times the yarns' relative sliding) and reaches a quarter
    of the yarn's thickness near 10°."""
    cell = crossover_cell(geometry_from_dict(repeat_doc(repeat=1)))
    t = cell.yarns["warp"].thickness
    m = [crossing_misfit(cell, math.radians(a)) for a in (0.0, 1.0, 2.0, 10.0)]
    assert m[0] < 1e-12
    assert 0.015 * t < m[1] < 0.04 * t
    assert m[2] == pytest.approx(2 * m[1], rel=0.1)
    assert 0.2 * t < m[3] < 0.3 * t
