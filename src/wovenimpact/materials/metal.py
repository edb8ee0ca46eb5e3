"""SI parameter set of the metals: J2 plasticity (blade, casing) and elastic (impactor).

MODEL.md §5; thesis 7.1.2 (Table 7-1, steel impactor), 8.2.3 (Table 8-1, titanium
blade), 8.3.1 (Table 8-2, aluminium casing). Plane-stress J2 with a piecewise-linear
isotropic hardening table; a point fails when its equivalent plastic strain reaches
``fracture_strain``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class MetalParameters:
    """Validated metal parameters (SI).

    Attributes:
        name: material name from the file.
        kind: ``"j2_plastic"`` or ``"elastic"``.
        density: ρ (kg/m³).
        modulus: Young's modulus E (Pa).
        poisson: ν (—), 0 ≤ ν < 0.5.
        hardening: ((ε_p, σ_y), ...) with ε_p (—) strictly increasing from 0 and σ_y
            (Pa) non-decreasing; one row = perfectly plastic; empty for ``"elastic"``.
        fracture_strain: equivalent plastic strain at failure (—), or None (no failure).
    """

    name: str
    kind: Literal["j2_plastic", "elastic"]
    density: float
    modulus: float
    poisson: float
    hardening: tuple[tuple[float, float], ...] = ()
    fracture_strain: float | None = None

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + ν)) (Pa)."""
        return self.modulus / (2.0 * (1.0 + self.poisson))

    @property
    def plane_stress_wave_speed(self) -> float:
        """c = √(E / (ρ (1 − ν²))) (m/s), the plate wave speed used for the stable step."""
        return (self.modulus / (self.density * (1.0 - self.poisson**2))) ** 0.5
