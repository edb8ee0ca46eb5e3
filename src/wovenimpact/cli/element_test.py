"""``wovenimpact element-test``: single-element tests of the crossover model (thesis ch. 6.3)."""

from __future__ import annotations

import dataclasses
import json
import math
from enum import Enum
from pathlib import Path

import typer

from wovenimpact.cli.app import app, emit, fail
from wovenimpact.errors import InputError, MaterialPointError


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
    material: Path = typer.Option(..., "--material", help="Fabric material TOML file."),
    out: Path = typer.Option(..., "--out", help="Output directory (history.csv, PNG figures)."),
    displacement: str = typer.Option(
        "0.06 mm", help="Maximum edge displacement of the extension tests (with unit)."
    ),
    angle: str = typer.Option("60 deg", help="Maximum shear angle of the shear tests (with unit)."),
    steps: int = typer.Option(600, min=1, help="Number of load steps."),
    homogenisation: Homogenisation = typer.Option(None, help="Override the material's."),
    shear_law: ShearLaw = typer.Option(None, "--shear-law", help="Override the material's."),
    frame: Frame = typer.Option(None, help="Override the material's."),
    failure: Failure = typer.Option(None, help="Override the material's."),
    softening_strain: float = typer.Option(None, help="Override Δε_s of progressive failure."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object with the results."),
) -> None:
    """Drive one unit cell (side 2ℓ0) through TEST; write history.csv, summary.json and figures."""
    from wovenimpact.calibration.element_plots import plot_element_test
    from wovenimpact.calibration.single_element import run_element_test, write_history_csv
    from wovenimpact.materials.fabric import FabricParameters
    from wovenimpact.spec import load_material
    from wovenimpact.units import to_si

    try:
        params = load_material(material)
        if not isinstance(params, FabricParameters):
            raise InputError(f"--material {material}: element tests need a woven_fabric material")
        overrides = {
            k: (v.value if isinstance(v, Enum) else v)
            for k, v in dict(
                homogenisation=homogenisation,
                shear=shear_law,
                frame=frame,
                failure=failure,
                softening_strain=softening_strain,
            ).items()
            if v is not None
        }
        if overrides:
            opts = dataclasses.replace(params.options, **overrides)
            if opts.failure == "progressive" and not opts.softening_strain > 0.0:
                raise InputError(
                    "--failure progressive needs --softening-strain > 0 "
                    f"(got {opts.softening_strain})"
                )
            params = dataclasses.replace(params, options=opts)
        if test.value in ("shear", "picture-frame"):
            amplitude = to_si(angle, "angle", "--angle")
        else:
            amplitude = to_si(displacement, "length", "--displacement")
        result = run_element_test(params, test.value, amplitude=amplitude, n_steps=steps)
    except (InputError, ValueError, MaterialPointError) as err:
        fail(str(err))
        return
    out.mkdir(parents=True, exist_ok=True)
    csv_path = write_history_csv(result, out / "history.csv")
    figures = plot_element_test(result, out)
    summary = result.summary()
    summary["history_csv"] = str(csv_path)
    summary["figures"] = [str(f) for f in figures]
    tmp = out / "summary.json.tmp"
    tmp.write_text(
        json.dumps({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                    for k, v in summary.items()}, indent=2)
    )
    tmp.replace(out / "summary.json")
    emit({k: v for k, v in summary.items() if k != "figures"}, as_json, f"element test: {test.value}")
