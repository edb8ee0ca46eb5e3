"""Shared fixtures: the reference Kevlar fabric of thesis Tables 5-1 and 7-2 (SI)."""

from __future__ import annotations

import dataclasses
import os

import pytest

from wovenimpact.jit import configure_threading
from wovenimpact.materials.crimp import crimp_amplitude
from wovenimpact.materials.fabric import FabricOptions, FabricParameters, YarnFamily

INCH = 0.0254
configure_threading()  # the CLI's threading layer in tests too (importing sets nothing)
# the tests' many scaled materials are not stored in the user's table cache (the disk
# cache has its own test, which turns it back on in a temporary folder)
os.environ.setdefault("WOVENIMPACT_TABLE_CACHE", "0")


def reference_fabric(**options) -> FabricParameters:
    """Thesis Table 7-2 in consistent units (T_u = 315 N, b = 0.98432 N), 27 tpi, 4.21 % crimp."""
    ell = 0.5 / (27 / INCH)
    yarn = YarnFamily(
        half_length=ell,
        crimp=0.0421,
        h0=crimp_amplitude(ell, 0.0421),
        area=0.149664e-6,
        modulus=96e9,
        ultimate_tension=315.0,
        width=0.9407e-3,
        thickness=0.2499e-3,
    )
    return FabricParameters(
        warp=yarn,
        fill=yarn,
        compaction_a=0.12389e-3,
        compaction_b=0.98432,
        shear_g1=0.0824e9,
        shear_g2=8.24e9,
        shear_c_max=0.65,
        fibre_density=1440.0,
        options=FabricOptions(**options),
    )


def with_options(params: FabricParameters, **options) -> FabricParameters:
    return dataclasses.replace(params, options=dataclasses.replace(params.options, **options))


@pytest.fixture
def kevlar() -> FabricParameters:
    return reference_fabric()
