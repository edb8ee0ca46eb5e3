"""``wovenimpact calibrate crimp|compression``: model parameters from measurements.

- ``crimp``: crimp amplitude h0 from thread count and crimp (thesis eq. 5.2–5.5, Table 5-1).
- ``compression``: a, b of the compaction law F = b·d/(a − d) from a force–compression
  curve (thesis eq. 5.8, §5.3.2, App. A), with a PNG of the fit.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from wovenimpact.cli.app import calibrate_app, emit, fail
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
