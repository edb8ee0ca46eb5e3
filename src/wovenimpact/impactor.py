"""Rigid impactors: bodies of revolution described by their meridian profile.

An impactor is the solid swept by its profile ρ = R(ζ) about its axis, ζ measured
from the nose tip (ζ = 0) back to the tail (ζ = L). Shapes (docs/model.md §4, issue 4):

- ``sphere``: R(ζ) = √(r² − (ζ − r)²), L = 2r;
- ``cylinder`` with a ``flat``, ``hemispherical``, ``conical`` or ``ogive`` (tangent
  ogive) nose of length ``nose_length``; an optional ``fillet`` radius rounds the edge
  of a flat nose.

The profile is sampled as a polyline of the closed meridian boundary (nose, shank,
flat tail), which the contact kernel uses for signed distances; mass, centre of
mass and moments of inertia are integrated over the same geometry (disc slices).
Default material: steel, ρ = 7922 kg/m³ (thesis Table 7-1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from wovenimpact.errors import InputError

STEEL_DENSITY = 7922.0  # kg/m³, thesis Table 7-1
# Penalty scale β of the body–node contact stiffness k = β m_node/Δt² (docs/theory.md
# §6.1): 0.3 keeps the early contact impulse within 1–6 % between the 0.94 and 0.47 mm
# plate meshes (0.1 left the coarse mesh 9–14 % short: the penalty lag ~Δt/√β grows
# with the element), with ω Δt = √β·… well below the stability limit of 2.
BODY_PENALTY_SCALE = 0.3
# A body flying sideways (``[impactor] axis``): its axis must be perpendicular to its
# travel to this |cos| (1e-9 rad), so that its shadow across the travel, which the
# outcome reads (quantities.intact_material_ahead), is the rectangle of its length and
# diameter
SIDEWAYS_COS = 1e-9
Nose = Literal["flat", "hemispherical", "conical", "ogive"]


@dataclass(frozen=True)
class Impactor:
    """A rigid body of revolution (SI).

    Attributes:
        shape: ``"sphere"`` or ``"cylinder"``.
        radius: r, the shank (or sphere) radius (m).
        length: L, total length tip to tail (cylinder only; m).
        nose: nose shape of a cylinder.
        nose_length: axial length of a hemispherical (= r), conical or ogive nose (m).
        fillet: edge radius of a flat nose (m), 0 for a sharp edge.
        density: ρ (kg/m³).
    """

    shape: Literal["sphere", "cylinder"]
    radius: float
    length: float = 0.0
    nose: Nose = "flat"
    nose_length: float = 0.0
    fillet: float = 0.0
    density: float = STEEL_DENSITY

    def __post_init__(self) -> None:
        r = self.radius
        if not r > 0.0:
            raise InputError(f"impactor radius = {r!r} m must be > 0")
        if not self.density > 0.0:
            raise InputError(f"impactor density = {self.density!r} kg/m³ must be > 0")
        if self.shape == "sphere":
            return
        if self.shape != "cylinder":
            raise InputError(f"impactor shape {self.shape!r}; valid: 'sphere', 'cylinder'")
        if self.nose not in ("flat", "hemispherical", "conical", "ogive"):
            raise InputError(f"impactor nose {self.nose!r}; valid: flat, hemispherical, "
                             "conical, ogive")
        nl = self.nose_axial_length
        if not self.length > nl:
            raise InputError(f"impactor length = {self.length!r} m must exceed the nose "
                             f"length {nl!r} m")
        if self.nose in ("conical", "ogive") and not self.nose_length > 0.0:
            raise InputError(f"a {self.nose} nose needs nose_length > 0 (got {self.nose_length!r})")
        if not 0.0 <= self.fillet < r or (self.fillet > 0.0 and self.nose != "flat"):
            raise InputError(f"impactor fillet = {self.fillet!r} m: valid 0 ≤ fillet < radius, "
                             "on a flat nose only")

    @property
    def total_length(self) -> float:
        return 2.0 * self.radius if self.shape == "sphere" else self.length

    @property
    def nose_axial_length(self) -> float:
        if self.shape == "sphere":
            return self.radius
        return {"flat": self.fillet, "hemispherical": self.radius}.get(self.nose, self.nose_length)

    def edge_radius(self, sideways: bool = False) -> float:
        """The smallest radius of curvature of the surface that strikes (m): a sphere's
        radius; a body flying sideways strikes with its side, the shank radius; nose
        first, a flat nose's fillet (0: a sharp rim), a hemispherical nose's radius, a
        conical or ogive nose's tip (0: pointed). A mesh resolves the contact only with
        elements well below it (:mod:`wovenimpact.results.mesh_verdict`)."""
        if self.shape == "sphere" or sideways or self.nose == "hemispherical":
            return self.radius
        return self.fillet if self.nose == "flat" else 0.0

    def radius_at(self, zeta):
        """R(ζ) of the profile (0 outside [0, L])."""
        z = np.asarray(zeta, dtype=float)
        r = self.radius
        if self.shape == "sphere":
            return np.sqrt(np.clip(r * r - (z - r) ** 2, 0.0, None)) * ((z >= 0) & (z <= 2 * r))
        out = np.full_like(z, r)
        n = self.nose
        if n == "hemispherical":
            nose = np.sqrt(np.clip(r * r - (r - z) ** 2, 0.0, None))
            out = np.where(z < r, nose, out)
        elif n == "conical":
            out = np.where(z < self.nose_length, r * z / self.nose_length, out)
        elif n == "ogive":
            ln = self.nose_length
            rho = (r * r + ln * ln) / (2.0 * r)  # tangent-ogive radius
            nose = np.sqrt(np.clip(rho * rho - (ln - z) ** 2, 0.0, None)) + r - rho
            out = np.where(z < ln, np.clip(nose, 0.0, None), out)
        elif self.fillet > 0.0:
            f = self.fillet
            nose = r - f + np.sqrt(np.clip(f * f - (f - z) ** 2, 0.0, None))
            out = np.where(z < f, nose, out)
        return np.where((z >= 0) & (z <= self.length), out, 0.0)

    def profile(self, n: int = 96) -> np.ndarray:
        """(m, 2) polyline (ζ, ρ) of the closed meridian boundary: from the tip on the
        axis along the nose and shank to the tail edge and back to the axis."""
        L = self.total_length
        nl = self.nose_axial_length
        if self.shape == "sphere":
            phi = np.linspace(0.0, math.pi, 2 * n + 1)
            pts = np.stack([self.radius * (1 - np.cos(phi)), self.radius * np.sin(phi)], axis=1)
            pts[-1] = (2.0 * self.radius, 0.0)  # exactly back on the axis
            return pts
        pts = [(0.0, 0.0)]
        if self.nose == "flat":
            if self.fillet > 0.0:
                f, r = self.fillet, self.radius
                pts.append((0.0, r - f))
                phi = np.linspace(0.0, 0.5 * math.pi, n // 4 + 2)[1:]
                pts += list(zip(f - f * np.cos(phi), r - f + f * np.sin(phi)))
            else:
                pts.append((0.0, self.radius))
        else:
            # cluster samples near the tip, where the curvature is largest
            s = (1 - np.cos(np.linspace(0.0, 0.5 * math.pi, n + 1)[1:]))
            z = nl * s
            pts += list(zip(z, self.radius_at(z)))
        pts.append((L, self.radius))
        pts.append((L, 0.0))
        return np.array(pts, dtype=float)

    def mass_properties(self, n: int = 20000) -> tuple[float, float, float, float]:
        """(mass, ζ of the centre of mass, I_axial, I_transverse about the centre) by
        midpoint integration over n disc slices (relative error ~1/n² for smooth noses)."""
        L = self.total_length
        dz = L / n
        z = (np.arange(n) + 0.5) * dz
        r = self.radius_at(z)
        dm = self.density * math.pi * r * r * dz
        mass = float(dm.sum())
        zc = float((dm * z).sum() / mass)
        i_axial = float((0.5 * dm * r * r).sum())
        i_trans = float((dm * (0.25 * r * r + (z - zc) ** 2)).sum() + (dm * dz * dz / 12.0).sum())
        return mass, zc, i_axial, i_trans


def fragment_simulating_projectile() -> Impactor:
    """The .22-calibre 17-grain fragment-simulating projectile of fabric-armour testing
    (docs/model.md §6): steel, 5.56 mm diameter, 1.1 g. Its chisel nose is not axisymmetric;
    here a flat-faced cylinder whose length gives 1.1 g at ρ = 7922 kg/m³ (5.72 mm)."""
    r = 0.5 * 5.56e-3
    length = 1.1e-3 / (STEEL_DENSITY * math.pi * r * r)
    return Impactor(shape="cylinder", radius=r, length=length, nose="flat")
