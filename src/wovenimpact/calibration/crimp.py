"""``calibrate crimp``: the crimp amplitude of thesis eq. (5.5) (:mod:`wovenimpact.materials.crimp`)
and the default shell thickness, from thread count and crimp."""

from __future__ import annotations

from dataclasses import dataclass

from wovenimpact.materials.crimp import crimp_amplitude, half_length_from_thread_count


@dataclass(frozen=True)
class CrimpCalibration:
    """Result of ``calibrate crimp``: half-length, amplitude and shell thickness (m)."""

    half_length_m: float
    h0_m: float
    thickness_m: float


def calibrate_crimp(crossing_thread_count: float, crimp: float) -> CrimpCalibration:
    """h0 from eq. (5.5) and the default shell thickness 4·h0 (thesis Table 5-1)."""
    ell = half_length_from_thread_count(crossing_thread_count)
    h0 = crimp_amplitude(ell, crimp)
    return CrimpCalibration(half_length_m=ell, h0_m=h0, thickness_m=4.0 * h0)
