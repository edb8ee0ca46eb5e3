"""Transverse impact of a flat rigid face on an elastic strip, against Smith's theory.

Verification of the impactor contact (docs/theory.md §6.2; issue: "contact that keeps
material under a face"). A heavy flat-faced cylinder (so its speed V barely changes)
strikes the middle of a straight elastic strip (ν = 0, width smaller than the face);
the theory of transverse impact on a linear-elastic string (Smith, McCrackin and
Schiefer, Textile Research Journal 28, 1958) gives, with c0 = √(E/ρ):

    V² = c0² (2 ε √(ε(1 + ε)) − ε²)             strain ε behind the longitudinal wave
    U = c0 (√(ε(1 + ε)) − ε)                     kink (transverse wave) speed, lab frame
    F = 2 E A ε sin θ,  tan θ = V / U            force on the projectile (two arms)

The face covers x ∈ [−a, a]: the material under it moves with it and the kinks start
at ±a. With ``edge = True`` the body is a cylinder of radius a lying across the strip
(its axis along the width, ``impactor.axis``) that strikes with its side, a round edge
of diameter 2a: the strip wraps it over |x| ≤ a sin θ and leaves it tangentially at θ,
so the force, the strain and the kink speed far from it are again Smith's. :func:`strip_impact` runs a quarter model (symmetry on x = 0 and y = 0, ends
clamped beyond the reach of the longitudinal wave) and measures, after the first
microsecond (the force: after ``settle``, 1 µs by default), the mean contact force, the
kink speed (the point where the deflection is half the face's travel moves at U), the
strain between face and kink, and how far the struck nodes stray from the face.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from wovenimpact.impactor import Impactor
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.model.model import RigidBody
from wovenimpact.results.quantities import impactor_row
from wovenimpact.solver import Workspace, step
from wovenimpact.state import initial_state


def smith_theory(modulus: float, density: float, speed: float) -> dict:
    """Strain ε, kink speed U (lab frame) and angle θ of Smith et al. (1958) for a
    linear-elastic string struck transversely at constant ``speed`` (module docstring)."""
    c0 = math.sqrt(modulus / density)

    def residual(eps):
        return c0 * c0 * (2.0 * eps * math.sqrt(eps * (1.0 + eps)) - eps * eps) - speed * speed

    eps = brentq(residual, 1e-12, 1.0, xtol=1e-15, rtol=1e-14)
    u = c0 * (math.sqrt(eps * (1.0 + eps)) - eps)
    return {"c0": c0, "strain": eps, "kink_speed": u, "sin_theta": speed / math.hypot(speed, u)}


@dataclass
class StripImpact:
    """The problem (SI). Defaults: a 0.5 mm steel-like strip 2 mm wide, 120 mm long,
    struck at 100 m/s by a 5 kg flat cylinder of radius 3 mm (ε ≈ 0.33 %). A string
    has no bending stiffness: the section's bending modulus is ``bending_ratio`` × E
    (flexural waves would otherwise carry the early load of a 0.5 mm plate)."""

    modulus: float = 210e9
    density: float = 7850.0
    thickness: float = 0.5e-3
    width: float = 2e-3
    length: float = 120e-3
    face_radius: float = 3e-3
    mass: float = 5.0
    speed: float = 100.0
    element_size: float = 0.125e-3
    end_time: float = 12e-6
    damping: float = 1.0
    membrane: str | None = None
    bending_ratio: float = 1e-4
    edge: bool = False  # a cylinder's side (radius face_radius) across the strip
    settle: float = 1e-6  # the means are taken from this long after the first contact

    def model(self):
        half_l, half_b = 0.5 * self.length, 0.5 * self.width
        nx = int(round(half_l / self.element_size))
        ny = max(1, int(round(half_b / self.element_size)))
        xs, ys = np.linspace(0.0, half_l, nx + 1), np.linspace(0.0, half_b, ny + 1)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        nodes = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
        idx = np.arange(gx.size).reshape(nx + 1, ny + 1)
        quads = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(),
                          idx[:-1, 1:].ravel()], axis=1)
        bc = BoundaryConditions(len(nodes))
        bc.symmetry(np.flatnonzero(nodes[:, 0] == 0.0), 0)
        bc.symmetry(np.flatnonzero(nodes[:, 1] == 0.0), 1)
        bc.fix(np.flatnonzero(np.isclose(nodes[:, 0], half_l)))
        steel = MetalParameters(name="strip", kind="elastic", density=self.density,
                                modulus=self.modulus, poisson=0.0)
        if self.edge:  # lying across the strip (axis y), centred on y = 0, longer than wide
            length = self.width + 4.0 * self.face_radius
            face = Impactor("cylinder", self.face_radius, length)
            tip = (0.0, -0.5 * length, 0.5 * self.thickness + 0.02e-3 + self.face_radius)
            body = RigidBody(face, tip=tip, direction=(0.0, 0.0, -1.0), speed=self.speed,
                             mass=self.mass, damping=self.damping, fraction=0.25,
                             axial_only=True, axis=(0.0, 1.0, 0.0))
        else:
            face = Impactor("cylinder", self.face_radius, 4.0 * self.face_radius)
            tip = (0.0, 0.0, 0.5 * self.thickness + 0.02e-3)
            body = RigidBody(face, tip=tip, direction=(0.0, 0.0, -1.0), speed=self.speed,
                             mass=self.mass, damping=self.damping, fraction=0.25,
                             axial_only=True)
        sec = Section(steel, thickness=self.thickness, membrane=self.membrane,
                      bending_modulus=self.bending_ratio * self.modulus)
        return build_model(nodes, quads, {"strip": sec}, np.zeros(len(quads), int), bcs=bc,
                           bodies=[body])


def theory_sin_theta(p: StripImpact) -> float:
    """sin θ of Smith's theory for the problem ``p``: where the strip leaves an edge."""
    return smith_theory(p.modulus, p.density, p.speed)["sin_theta"]


def half_deflection_point(x, w, half, start):
    """The first x beyond ``start`` where the deflection w (ordered along x) falls below
    ``half``, linearly interpolated; NaN before any travel."""
    j = np.flatnonzero((w < half) & (x > start))
    if half <= 0.0 or not j.size or j[0] == 0 or not w[j[0] - 1] > w[j[0]]:
        return math.nan
    j = j[0]
    return float(x[j - 1] + (w[j - 1] - half) / (w[j - 1] - w[j]) * (x[j] - x[j - 1]))


def strip_impact(problem: StripImpact | None = None) -> dict:
    """Run the strip impact and compare it with :func:`smith_theory`; returns the
    measured and theoretical figures and the sampled histories (for the figure)."""
    p = problem or StripImpact()
    model = p.model()
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    theory = smith_theory(p.modulus, p.density, p.speed)
    x0 = model.x0
    axis_nodes = np.flatnonzero(x0[:, 1] == 0.0)
    axis_nodes = axis_nodes[np.argsort(x0[axis_nodes, 0])]
    # the nodes the face carries: under a flat face |x| < a; on an edge those the strip
    # wraps it with, |x| < a sin θ
    reach = p.face_radius * (theory_sin_theta(p) if p.edge else 1.0)
    under = np.flatnonzero(x0[:, 0] <= reach - 1e-12)
    times, forces, kinks, stray = [], [], [], []
    t_contact = None
    while st.t < p.end_time:
        step(model, st, ws)
        row = impactor_row(model, st)
        travel = float(row["impactor_displacement_m"]) - 0.02e-3  # face travel since contact
        if t_contact is None and row["contact_force_full_N"] > 0.0:
            t_contact = st.t
        times.append(st.t)
        forces.append(row["contact_force_full_N"])
        w = -(st.x[axis_nodes, 2] - x0[axis_nodes, 2])
        x = st.x[axis_nodes, 0]  # laboratory positions: U is the kink's lab speed
        kinks.append(half_deflection_point(x, w, 0.5 * travel, reach))
        if p.edge:  # the cylinder's surface below each node (its axis is its centre line)
            face_z = st.bodies[0, RB.B_X + 2] - np.sqrt(np.maximum(
                p.face_radius**2 - (st.x[under, 0] - st.bodies[0, RB.B_X]) ** 2, 0.0))
        else:
            face_z = st.bodies[0, RB.B_X + 2] - model.body_params[0, RB.BP_TIP]
        stray.append(float(np.max(np.abs(st.x[under, 2] - (face_z - 0.5 * p.thickness)))))
    t = np.array(times)
    f = np.array(forces)
    kink = np.array(kinks)
    settle = (t_contact or 0.0) + p.settle
    late = t >= settle
    f_theory = 2.0 * p.modulus * p.width * p.thickness * theory["strain"] * theory["sin_theta"]
    # kink speed: the half-deflection point sits at a + U t/2, so U is twice the slope
    # of a least-squares line through its positions after the first microsecond, once
    # it is four elements past the face's edge (before that the kink is not resolved)
    ok = (t >= (t_contact or 0.0) + 1e-6) & np.isfinite(kink)
    ok &= kink > reach + 4.0 * p.element_size
    slope = 2.0 * float(np.polyfit(t[ok], kink[ok], 1)[0]) if ok.sum() > 2 else math.nan
    # strain of the elements between the face and the kink at the end
    e_x = np.linalg.norm(st.elem[:, [0, 2]], axis=1) - 1.0  # |F e1| − 1 (corotational F)
    cx = st.x[model.quads].mean(axis=1)[:, 0]
    between = (cx > reach + 2 * p.element_size) & (cx < kink[-1] - 2 * p.element_size)
    return {
        "theory": {**theory, "force_N": f_theory},
        "force_N": float(np.mean(f[late])),
        "force_error": float(np.mean(f[late]) / f_theory - 1.0),
        "kink_speed_m_per_s": slope,
        "kink_speed_error": slope / theory["kink_speed"] - 1.0,
        "strain": float(np.mean(e_x[between])) if between.any() else math.nan,
        "strain_error": float(np.mean(e_x[between]) / theory["strain"] - 1.0)
        if between.any() else math.nan,
        "max_stray_from_face_m": float(np.max(np.array(stray)[t >= (t_contact or 0.0)])),
        "thickness_m": p.thickness,
        "face_radius_m": p.face_radius,
        "contact_half_width_m": reach,
        "first_contact_s": t_contact,
        "history": {"time_s": t, "contact_force_N": f, "kink_position_m": kink,
                    "stray_m": np.array(stray)},
    }

