"""``wovenimpact element-test``: single-element tests of a material.

A ``woven_fabric`` material runs the crossover-model tests of thesis ch. 6.3
(:mod:`wovenimpact.calibration.single_element`); a ``j2_plastic`` metal runs
plane-stress uniaxial, biaxial or shear tests to fracture
(:mod:`wovenimpact.calibration.metal_element`).
"""

from __future__ import annotations

import dataclasses
import json
import math
from enum import Enum
from pathlib import Path

import typer

from wovenimpact.cli.app import app, emit, fail
from wovenimpact.errors import InputError, MaterialPointError


MAX_STRAIN_RATE = 1e8  # 1/s: the Johnson–Cook rate terms are checked up to this


class Test(str, Enum):
    uniaxial = "uniaxial"
    uniaxial_free = "uniaxial-free"
    biaxial = "biaxial"
    shear = "shear"
    picture_frame = "picture-frame"


class Homogenisation(str, Enum):
    """``--homogenisation``: how crossover forces become membrane resultants."""

    virial = "virial"
    thesis = "thesis"


class ShearLaw(str, Enum):
    """``--shear-law``: the trellis shear law."""

    true = "true"
    thesis = "thesis"


class Frame(str, Enum):
    """``--frame``: the frame the yarn directions follow."""

    fibre = "fibre"
    green_naghdi = "green-naghdi"


class Failure(str, Enum):
    """``--failure``: yarn failure, instantaneous or with softening."""

    instant = "instant"
    progressive = "progressive"


@app.command("element-test")
def element_test(
    test: Test = typer.Argument(..., help="Which deformation history to apply."),
    material: Path = typer.Option(
        ..., "--material", help="Material TOML file: woven_fabric or j2_plastic."
    ),
    out: Path = typer.Option(..., "--out", help="Output directory (history.csv, PNG figures)."),
    displacement: str = typer.Option(
        None, help="Fabric: maximum edge displacement of the extension tests (with unit; "
        "default 0.06 mm)."
    ),
    angle: str = typer.Option(
        "60 deg", help="Fabric: maximum shear angle of the shear tests (with unit)."
    ),
    strain: float = typer.Option(
        None, help="Metal: final log strain (uniaxial 0.4, biaxial 0.25) or shear γ (1.0); "
        "the test stops at fracture."
    ),
    strain_rate: str = typer.Option(
        "0.001 1/s", "--strain-rate", help="Metal: rate of the applied strain (with unit)."
    ),
    thickness: str = typer.Option("1 mm", help="Metal: reference thickness t0 (with unit)."),
    steps: int = typer.Option(None, min=1, max=1_000_000,
                              help="Number of load steps (fabric 600, metal 400)."),
    homogenisation: Homogenisation = typer.Option(None, help="Fabric: override the material's."),
    shear_law: ShearLaw = typer.Option(
        None, "--shear-law", help="Fabric: override the material's."
    ),
    frame: Frame = typer.Option(None, help="Fabric: override the material's."),
    failure: Failure = typer.Option(None, help="Fabric: override the material's."),
    softening_strain: float = typer.Option(None, help="Override Δε_s of progressive failure."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object with the results."),
) -> None:
    """Drive one point through TEST; write history.csv, summary.json and figures.

    Fabric: one unit cell (side 2ℓ0). Metal: one plane-stress J2 point at a constant
    strain rate until it fails (uniaxial: the lateral resultant solved to zero).
    """
    from wovenimpact.calibration.element_plots import plot_element_test, plot_metal_element_test
    from wovenimpact.calibration.metal_element import run_metal_element_test
    from wovenimpact.calibration.metal_element import write_history_csv as write_metal_csv
    from wovenimpact.calibration.single_element import run_element_test, write_history_csv
    from wovenimpact.materials.fabric import FabricParameters
    from wovenimpact.materials.metal import MetalParameters
    from wovenimpact.spec import load_material
    from wovenimpact.io.outdir import prepare_output_dir
    from wovenimpact.units import to_si

    try:
        prepare_output_dir(out)
        # every quantity flag is checked, also one the chosen test does not use
        angle_si = to_si(angle, "angle", "--angle", gt=0, le=math.pi / 2)
        rate_si = to_si(strain_rate, "strain_rate", "--strain-rate", gt=0, le=MAX_STRAIN_RATE)
        thickness_si = to_si(thickness, "length", "--thickness", ge=1e-6, le=1.0)
        if softening_strain is not None and not 0.0 < softening_strain < 1.0:
            raise InputError(f"--softening-strain = {softening_strain} is not valid: it must "
                             "be > 0 and < 1 (e.g. 0.01)")
        params = load_material(material)
        if isinstance(params, MetalParameters):
            _check_metal_options(params, material, test, strain, dict(
                displacement=displacement, homogenisation=homogenisation,
                shear_law=shear_law, frame=frame, failure=failure,
                softening_strain=softening_strain))
            metal = run_metal_element_test(
                params,
                test.value,
                strain=strain,
                n_steps=400 if steps is None else steps,
                strain_rate=rate_si,
                thickness=thickness_si,
            )
    except (InputError, ValueError, MaterialPointError) as err:
        fail(str(err))
        return
    if isinstance(params, MetalParameters):
        _write_outputs(out, metal, write_metal_csv, plot_metal_element_test, test, as_json)
        return
    try:
        if not isinstance(params, FabricParameters):
            raise InputError(f"--material {material}: element tests need a woven_fabric material")
        if strain is not None:
            raise InputError("--strain is a metal option: give --displacement or --angle")
        steps = 600 if steps is None else steps
        params = _with_overrides(params, dict(homogenisation=homogenisation, shear=shear_law,
                                              frame=frame, failure=failure,
                                              softening_strain=softening_strain))
        amplitude = (angle_si if test.value in ("shear", "picture-frame") else
                     _extension_amplitude(params, displacement))
        result = run_element_test(params, test.value, amplitude=amplitude, n_steps=steps)
    except (InputError, ValueError, MaterialPointError) as err:
        fail(str(err))
        return
    _write_outputs(out, result, write_history_csv, plot_element_test, test, as_json)


def _check_metal_options(params, material: Path, test: Test, strain, fabric_only: dict) -> None:
    """A metal element test's options: no fabric option given, a j2_plastic material, a
    metal test, a positive strain (InputError naming the flag otherwise)."""
    from wovenimpact.calibration.metal_element import METAL_TESTS

    given = [k.replace("_", "-") for k, v in fabric_only.items() if v is not None]
    if given:
        raise InputError(
            f"--{', --'.join(given)}: fabric options, not valid with the metal "
            f"{material} (use --strain, --strain-rate, --thickness)"
        )
    if params.kind != "j2_plastic":
        raise InputError(
            f"--material {material}: kind {params.kind!r} has no plasticity to test; "
            "element tests need woven_fabric or j2_plastic"
        )
    if test.value not in METAL_TESTS:
        raise InputError(
            f"test {test.value!r} is not valid for a metal: choose one of "
            f"{', '.join(METAL_TESTS)}"
        )
    if strain is not None and not strain > 0.0:
        raise InputError(f"--strain = {strain} is not valid: it must be > 0")


def _with_overrides(params, options: dict):
    """The fabric's parameters with the options given on the command line (None: the
    material's own); progressive failure needs a softening strain > 0."""
    overrides = {k: (v.value if isinstance(v, Enum) else v)
                 for k, v in options.items() if v is not None}
    if not overrides:
        return params
    opts = dataclasses.replace(params.options, **overrides)
    if opts.failure == "progressive" and not opts.softening_strain > 0.0:
        raise InputError(
            "--failure progressive needs --softening-strain > 0 "
            f"(got {opts.softening_strain})"
        )
    return dataclasses.replace(params, options=opts)


def _extension_amplitude(params, displacement: str | None) -> float:
    """The extension tests' largest edge displacement (SI; default 0.06 mm), at most the
    unit cell's side 2ℓ0."""
    from wovenimpact.units import to_si

    displacement = "0.06 mm" if displacement is None else displacement
    amplitude = to_si(displacement, "length", "--displacement", gt=0)
    cell = 2.0 * min(params.warp.half_length, params.fill.half_length)
    if amplitude > cell:
        raise InputError(f"--displacement = {displacement!r} is more than the unit "
                         f"cell's side 2ℓ0 = {cell * 1e3:.4g} mm (100 % strain; the "
                         f"yarns break near 2 %) (valid: up to {cell * 1e3:.4g} mm)")
    return amplitude


def _write_outputs(out: Path, result, write_csv, plot, test: Test, as_json: bool) -> None:
    """history.csv, the figures and summary.json into ``out``; print the summary (a
    failed write, e.g. a full disk, is a one-line error)."""
    from wovenimpact.io.outdir import write_failure

    try:
        _write_files(out, result, write_csv, plot, test, as_json)
    except OSError as err:
        fail(write_failure(err, f"the element test into {out}"))


def _write_files(out: Path, result, write_csv, plot, test: Test, as_json: bool) -> None:
    out.mkdir(parents=True, exist_ok=True)
    csv_path = write_csv(result, out / "history.csv")
    figures = plot(result, out)
    summary = result.summary()
    summary["history_csv"] = str(csv_path)
    summary["figures"] = [str(f) for f in figures]
    tmp = out / "summary.json.tmp"
    tmp.write_text(
        json.dumps({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                    for k, v in summary.items()}, indent=2)
    )
    tmp.replace(out / "summary.json")
    shown = {k: v for k, v in summary.items() if k != "figures"}
    emit(shown, as_json, f"element test: {test.value}")
