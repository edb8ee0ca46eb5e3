"""``wovenimpact calibrate crimp|compression|fracture|crossover``: model parameters from
measurements and virtual tests.

- ``crimp``: crimp amplitude h0 from thread count and crimp (thesis eq. 5.2–5.5, Table 5-1).
- ``compression``: a, b of the compaction law F = b·d/(a − d) from a force–compression
  curve (thesis eq. 5.8, §5.3.2, App. A), with a PNG of the fit.
- ``fracture``: the element-size regularisation of a metal's fracture strain, fitted on
  a simulated tension test at several meshes (docs/theory.md §7.3), written as the
  material file's ``[material.regularisation]`` with a CSV and a figure.
- ``crossover``: a fabric material file from the 3-D crossover cell's virtual tests
  (compression → a, b; uniaxial extension → the yarns' modulus), with the round trip of
  the written file's single-element tests against the cell (docs/solid.md §6.6).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from wovenimpact.cli.app import calibrate_app, emit, err_console, fail
from wovenimpact.errors import InputError


def _fail_input(err: InputError) -> None:
    fail(str(err))  # `fail` escapes rich markup ("[length]" stays visible)


@calibrate_app.command("crimp")
def crimp(
    thread_count: Annotated[
        str,
        typer.Option(
            "--thread-count",
            help=(
                "Thread count of the CROSSING yarn family, with unit, e.g. '27 1/in' or "
                "'10.63 1/cm'. The half-length of a yarn between crossings is "
                "ℓ0 = 1/(2 n_crossing). For a balanced fabric both families have the same count."
            ),
        ),
    ],
    crimp_value: Annotated[
        str,
        typer.Option(
            "--crimp", help="Crimp c = yarn length / fabric length − 1, e.g. 0.0421 or '4.21 %'."
        ),
    ],
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object (SI units).")
    ] = False,
) -> None:
    """Crimp amplitude h0 of eq. (5.5) and the default shell thickness 4·h0 (Table 5-1)."""
    from wovenimpact.calibration.crimp import calibrate_crimp
    from wovenimpact.spec.material import MAX_CRIMP
    from wovenimpact.units import to_si

    try:
        n = to_si(thread_count, "inverse_length", "--thread-count", gt=0.0)
        c = to_si(crimp_value, "dimensionless", "--crimp", ge=0.0, le=MAX_CRIMP)
    except InputError as err:
        _fail_input(err)
    result = calibrate_crimp(n, c)
    emit(
        {
            "half_length_m": result.half_length_m,
            "h0_m": result.h0_m,
            "thickness_m": result.thickness_m,
        },
        as_json,
        "Crimp amplitude, thesis eq. (5.5)",
    )


@calibrate_app.command("compression")
def compression(
    data: Annotated[
        Path,
        typer.Argument(
            help="CSV with a header naming columns with units: d_m,F_N or d_mm,F_mN or d_mm,F_N."
        ),
    ],
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for the plot (default: next to the data file)."),
    ] = None,
    weighting: Annotated[
        str,
        typer.Option(
            "--weighting",
            help="'relative' residuals (F error ∝ F) or 'absolute' (the thesis's App. A cost).",
        ),
    ] = "relative",
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object (SI units).")
    ] = False,
) -> None:
    """Fit a, b of F = b·d/(a − d) (eq. 5.8) to DATA and save a plot of the fit."""
    from wovenimpact.calibration.compression import (
        fit_compression,
        plot_compression_fit,
        read_compression_csv,
    )
    from wovenimpact.io.outdir import prepare_output_dir, write_failure

    try:
        if weighting not in ("relative", "absolute"):
            raise InputError(
                f"--weighting = {weighting!r} is not valid: use 'relative' or 'absolute'"
            )
        out_dir = data.parent if out is None else out
        prepare_output_dir(out_dir)
        measured = read_compression_csv(data)
        fit = fit_compression(measured.d_m, measured.F_N, measured.source, weighting)
    except InputError as err:
        _fail_input(err)
    try:
        plot = plot_compression_fit(measured, fit, out_dir / f"{data.stem}_fit.png")
    except OSError as err:
        _fail_input(InputError(write_failure(err, "the plot")))
    emit(
        {
            "a_m": fit.a_m,
            "b_N": fit.b_N,
            "r2": fit.r2,
            "rmse_N": fit.rmse_N,
            "n_points": fit.n_points,
            "weighting": fit.weighting,
            "plot": str(plot),
        },
        as_json,
        "Compaction law F = b·d/(a − d), thesis eq. (5.8)",
    )


@calibrate_app.command("fracture")
def fracture(
    material: Annotated[
        Path,
        typer.Argument(help="A j2_plastic material file (fracture_strain or [material.damage])."),
    ],
    out: Annotated[
        Path,
        typer.Option("--out", help="Directory for the regularised material file, CSV and figure."),
    ],
    sizes: Annotated[
        str | None,
        typer.Option(
            "--sizes",
            help=(
                "Element sizes of the coupon meshes, comma-separated with units, e.g. "
                "'0.5 mm, 1 mm, 2 mm'; the finest is the reference. Each must divide the "
                "coupon's length (32 t) and width (8 t). Default: 0.25, 0.5, 1, 2, 4 × t."
            ),
        ),
    ] = None,
    thickness: Annotated[
        str,
        typer.Option("--thickness", help="Coupon thickness t, e.g. '1 mm' (plan: 32 t × 8 t)."),
    ] = "1 mm",
    reference_length: Annotated[
        str | None,
        typer.Option(
            "--reference-length",
            help=(
                "reference_length written in the file, where s = 1 (e.g. the element size "
                "the material's examples use); default: the finest size."
            ),
        ),
    ] = None,
    failure_displacement: Annotated[
        str | None,
        typer.Option(
            "--failure-displacement",
            help=(
                "Soften after onset over this plastic displacement (e.g. '0.05 mm') in "
                "every run; default: off."
            ),
        ),
    ] = None,
    speed: Annotated[
        str, typer.Option("--speed", help="Speed of the pulled end, e.g. '10 m/s'.")
    ] = "10 m/s",
    threads: Annotated[
        int,
        typer.Option("--threads", min=1, help="Kernel threads (a coupon is small: 1 is fastest)."),
    ] = 1,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object (SI units).")
    ] = False,
) -> None:
    """Fit the element-size regularisation of a metal's fracture strain (docs/theory.md
    §7.3) on a simulated quasi-static tension test of a flat coupon at several meshes:
    each mesh's scale s makes it fracture at the finest mesh's elongation. Writes
    MATERIAL_regularised.toml (the file with the fitted [material.regularisation]),
    MATERIAL_fracture.csv and MATERIAL_fracture.png into --out."""
    from wovenimpact.calibration.fracture_regularisation import calibrate, write_calibration
    from wovenimpact.io.outdir import prepare_output_dir, write_failure
    from wovenimpact.jit import capped_threads, set_threads

    try:
        coupon, hs, l_ref, u_f = _fracture_inputs(material, sizes, thickness, speed,
                                                  reference_length, failure_displacement)
        prepare_output_dir(out)
    except InputError as err:
        _fail_input(err)
    import numba

    before = numba.get_num_threads()
    set_threads(capped_threads(threads, "--threads"))
    say = None if as_json else (lambda msg: typer.echo(msg, err=True))
    try:
        cal = calibrate(coupon, hs, failure_displacement=u_f, progress=say)
    finally:
        set_threads(before)  # a program calling the command keeps its own setting
    try:
        paths = write_calibration(cal, material, out, l_ref)
    except OSError as err:
        _fail_input(InputError(write_failure(err, "the calibration")))
    result = _fracture_result(cal, l_ref, paths)
    if as_json:
        typer.echo(json.dumps(result))
        return
    emit({k: (str(v) if isinstance(v, list) else v) for k, v in result.items()}, False,
         "Fracture regularisation, docs/theory.md §7.3")


def _fracture_inputs(material: Path, sizes: str | None, thickness: str, speed: str,
                     reference_length: str | None, failure_displacement: str | None):
    """``calibrate fracture``'s options in SI and the coupon: (coupon, element sizes,
    reference length or None, softening displacement); an InputError names the option."""
    from wovenimpact.calibration.fracture_regularisation import DEFAULT_SIZES, Coupon
    from wovenimpact.materials.metal import MetalParameters
    from wovenimpact.spec.material import load_material
    from wovenimpact.units import to_si

    t = to_si(thickness, "length", "--thickness", gt=0.0, example="1 mm")
    v = to_si(speed, "velocity", "--speed", gt=0.0, example="10 m/s")
    if sizes is None:
        hs = [k * t for k in DEFAULT_SIZES]
    else:
        hs = [to_si(s.strip(), "length", "--sizes", gt=0.0, example="0.5 mm")
              for s in sizes.split(",") if s.strip()]
    l_ref = (None if reference_length is None else
             to_si(reference_length, "length", "--reference-length", gt=0.0))
    u_f = (0.0 if failure_displacement is None else
           to_si(failure_displacement, "length", "--failure-displacement", gt=0.0))
    mat = load_material(material)
    if not isinstance(mat, MetalParameters) or mat.kind != "j2_plastic":
        raise InputError(f"{material}: a fracture calibration needs a j2_plastic material")
    if mat.fracture_strain is None and mat.damage is None:
        raise InputError(f"{material}: the material has no fracture strain and no "
                         "[material.damage] table: there is no fracture to regularise")
    coupon = Coupon(mat, thickness=t, speed=v)
    if len(hs) < 2 or len(set(hs)) != len(hs):
        raise InputError(f"--sizes: give at least two different element sizes (got "
                         f"{', '.join(f'{h * 1e3:g} mm' for h in hs)})")
    for h in hs:
        try:
            coupon.check_size(h)
        except InputError as err:
            raise InputError(f"--sizes: {err}") from None
    return coupon, hs, l_ref, u_f


def _fracture_result(cal, l_ref: float | None, paths: dict) -> dict:
    """``calibrate fracture``'s answer (SI): the reference, the table as shipped, the
    largest elongation errors before and after, the files written."""
    from wovenimpact.calibration.fracture_regularisation import calibration_rows, shipped_table

    l_ship = cal.reference_size if l_ref is None else l_ref
    rows = calibration_rows(cal)
    return {
        "reference_size_m": cal.reference_size,
        "reference_elongation_at_fracture_m": cal.reference.elongation_at_fracture,
        "reference_length_m": l_ship,
        "fracture_scale": [list(r) for r in shipped_table(cal, l_ship)],
        "largest_error_before": max(abs(r["error_before"]) for r in rows),
        "largest_error_after": max(abs(r["error_after"]) for r in rows),
        "wall_s": cal.wall_s,
        **{f"{k}_file": str(p) for k, p in paths.items()},
    }


@calibrate_app.command("crossover")
def crossover(
    geometry: Annotated[Path, typer.Argument(help="The cell's geometry file, e.g. "
                                                  "examples/crossover/thesis_cell.toml.")],
    yarn: Annotated[Path, typer.Option("--yarn", help="The yarn's transversely isotropic "
                                       "material file, e.g. "
                                       "examples/materials/kevlar_yarn_solid.toml.")],
    template: Annotated[Path, typer.Option("--template", help="A fabric material file whose "
                                           "strength, shear law and options are kept, e.g. "
                                           "examples/materials/kevlar_thesis.toml.")],
    out: Annotated[Path, typer.Option("--out", help="Directory for fabric.toml, "
                                      "crossover_calibration.json and the figures.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object (SI units).")
                       ] = False,
) -> None:
    """Calibrate a fabric from the 3-D crossover cell (thesis ch. 5): squeeze the cell to
    3 N between rigid plates (→ the compaction law's a, b), pull its warp to 1 % (→ the
    yarns' modulus E1), and write the template fabric file with those values and the
    geometry's thread counts, crimps, widths, thicknesses and section areas, each line
    with its source. Prints the round trip: the written file's single-element tests
    against the cell. A few minutes on the thesis's cell."""
    from wovenimpact.calibration.crossover_calibration import calibrate_crossover
    from wovenimpact.io.outdir import write_failure

    try:
        doc = calibrate_crossover(geometry, yarn, template, out)
    except InputError as err:
        _fail_input(err)
    except OSError as err:
        fail(write_failure(err, str(out)))
    summary = {"fabric_file": str(out / doc["fabric_file"]), "E1_Pa": doc["e1_Pa"],
               "a_m": doc["a_m"], "b_N": doc["b_N"], "fit_r2": doc["fit_r2"]}
    for row in doc["round_trip"]:
        summary[f"round_trip {row['test']} at {row['at']}"] = f"{row['error']:+.1%}"
    emit(summary, as_json, title=f"crossover calibration: {geometry.name}")
    if not as_json:
        for warning in doc["warnings"]:
            err_console.print(f"warning: {warning}", highlight=False, markup=False)
