"""``wovenimpact calibrate crossover``: a fabric material file from the 3-D crossover cell's
virtual tests (docs/solid.md §6.6).

The route of the thesis's chapter 5: the cell of a geometry file (spec.crossover) with a
transversely isotropic yarn is

1. squeezed between rigid plates with the thesis's end conditions until the yarns press
   each other with 3 N (calibration.cell_compression, ``ends = "thesis"``, ``measure =
   "yarns"``) → the compaction law's a, b (eq. 5.8, ``calibrate compression``'s fit);
2. pulled along the warp with the fill's ends held to a strain of 1 %
   (calibration.cell_extension) → E1, the modulus of the middle of the pulled yarn (eq.
   5.6), the yarns' modulus of the shell model.

The fabric file written is a *template* fabric file with, in ``[material.warp]`` and
``[material.fill]``, the thread count, crimp, width, thickness and the yarn's section
area of the geometry, the modulus E1, and in ``[material.compaction]`` a and b, each line
followed by a comment naming its source, and the ultimate tension as the template yarn's
strength T_u / A times the cell's section; what the cell does not give (the shear law, the
options) stays the template's, and the file says so. The fill's modulus is the warp's E1
(one yarn material; the fill is not pulled).

The *round trip* (:func:`round_trip`): the written file's single-element tests (the
shell's yarn model, calibration.single_element) against the cell — the uniaxial test
(warp edge displaced, fill length held) and the equibiaxial test, the yarn tension
against the cell's end force at strains of 0.5 and 1 %, and the compaction law against
the cell's compression curve at 1, 2 and 3 N.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from wovenimpact.calibration.cell_compression import compress_cell
from wovenimpact.calibration.cell_extension import extend_cell
from wovenimpact.errors import InputError
from wovenimpact.io.atomic import atomic_write_text
from wovenimpact.model.crossover_cell import crossover_cell, section_area

ROUND_TRIP_STRAINS = (0.005, 0.01)
ROUND_TRIP_FORCES = (1.0, 2.0, 3.0)  # N


def set_values(text: str, values: dict[tuple[str, str], tuple[str, str]]) -> str:
    """``text`` (a TOML file) with the line ``key = …`` of each table replaced by ``key =
    value  # comment`` (``values[(table, key)] = (value, comment)``); an InputError names
    a table or key the text does not hold. Other lines, comments included, are kept."""
    lines = text.splitlines()
    table = ""
    done = set()
    for i, line in enumerate(lines):
        head = re.match(r"\s*\[([^\]]+)\]\s*(#.*)?$", line)
        if head:
            table = head.group(1).strip()
            continue
        m = re.match(r"(\s*)([A-Za-z0-9_]+)\s*=", line)
        if m and (table, m.group(2)) in values:
            value, comment = values[(table, m.group(2))]
            lines[i] = f"{m.group(1)}{m.group(2)} = {value}  # {comment}"
            done.add((table, m.group(2)))
    missing = sorted(set(values) - done)
    if missing:
        raise InputError(f"the template has no {missing[0][1]!r} in [{missing[0][0]}]: a "
                         "fabric file with warp, fill and compaction tables is needed")
    return "\n".join(lines) + "\n"


def drop_header(text: str) -> str:
    """``text`` without the comment and blank lines before its first table."""
    lines = text.splitlines()
    first = next((i for i, line in enumerate(lines) if line.lstrip().startswith("[")), 0)
    return "\n".join(lines[first:]) + "\n"


def _q(x: float, unit: str, scale: float, digits: int = 6) -> str:
    return f'"{x * scale:.{digits}g} {unit}"'


def cell_values(geometry, compression, extension,
                template=None) -> dict[tuple[str, str], tuple[str, str]]:
    """The fabric file's values the cell gives (module docstring), with their sources;
    with the ``template``'s FabricParameters, each family's ultimate tension too: the
    template yarn's strength T_u / A times the cell's section (the same fibre, another
    yarn size)."""
    cell = crossover_cell(geometry)
    values = {}
    if compression.fit is None:
        raise InputError("the cell's compression curve does not fit F = b d / (a − d): no "
                         "compaction law to write (a finer cell or a slower press?)")
    for name, spec in zip(("warp", "fill"), geometry.families):
        shape = cell.yarns[name]
        area = section_area(cell.shape, cell.trim, shape.width, shape.thickness)
        t = f"material.{name}"
        src = "the geometry file"
        values[(t, "thread_count")] = (_q(spec.thread_count, "1/in", 0.0254), src)
        values[(t, "crimp")] = (f"{shape.crimp:.6g}", src + " (the centreline's crimp)")
        values[(t, "width")] = (_q(shape.width, "mm", 1e3), src)
        values[(t, "thickness")] = (_q(shape.thickness, "mm", 1e3), src)
        values[(t, "area")] = (_q(area, "mm^2", 1e6), "the trimmed section's area")
        values[(t, "modulus")] = (_q(extension.e1, "GPa", 1e-9, 5),
                                  "E1 of the cell's uniaxial extension (eq. 5.6)"
                                  + ("" if name == "warp" else ", the warp's: one yarn"))
        if template is not None:
            own = getattr(template, name)
            strength = own.ultimate_tension / own.area
            values[(t, "ultimate_tension")] = (
                _q(strength * area, "N", 1.0, 5),
                f"the template yarn's strength T_u/A = {strength * 1e-6:.5g} MPa × this area")
    fit = compression.fit
    values[("material.compaction", "a")] = (
        _q(fit.a_m, "mm", 1e3, 5), f"the cell squeezed to 3 N (eq. 5.8 fit, r² {fit.r2:.3f})")
    values[("material.compaction", "b")] = (
        _q(fit.b_N, "N", 1.0, 5), "the same fit")
    return values


def shell_tests(params, side: float) -> dict[str, dict]:
    """The written file's single-element uniaxial and equibiaxial tests (the shell's yarn
    model, calibration.single_element) to the largest round-trip strain of a cell of side
    ``side``: {test: history}, read by :func:`round_trip` and the figure."""
    from wovenimpact.calibration.single_element import run_element_test

    return {test: run_element_test(params, test, amplitude=max(ROUND_TRIP_STRAINS) * side,
                                   n_steps=400).history
            for test in ("uniaxial", "biaxial")}


def round_trip(shell: dict[str, dict], side: float, compression, extension,
               biaxial) -> list[dict]:
    """Rows (test, at, cell, shell, error) of the written file's single-element tests
    (``shell``, :func:`shell_tests`) against the cell (module docstring)."""
    rows = []
    for test, cell_run in (("uniaxial", extension), ("biaxial", biaxial)):
        h = shell[test]
        eps = np.asarray(h["displacement_m"]) / side
        for e in ROUND_TRIP_STRAINS:
            shell_force = float(np.interp(e, eps, h["tension_w_N"]))
            cell = float(np.interp(e, cell_run.strain, cell_run.force))
            rows.append({"test": test, "at": f"strain {e:.3g}", "cell_N": cell,
                         "shell_N": shell_force, "error": shell_force / cell - 1.0})
    fit = compression.fit
    for f in ROUND_TRIP_FORCES:
        d_cell = float(np.interp(f, compression.force, compression.d))
        d_law = fit.a_m * f / (fit.b_N + f)
        rows.append({"test": "compression", "at": f"{f:g} N", "cell_mm": d_cell * 1e3,
                     "shell_mm": d_law * 1e3, "error": d_law / d_cell - 1.0})
    return rows


# a virtual test is trusted when quasi-static and its hourglass energy small (issue bounds)
MAX_KINETIC, MAX_HOURGLASS, MAX_ENERGY_ERROR = 0.01, 0.05, 0.01


def check_warnings(checks: dict) -> list[str]:
    """A sentence for each run whose kinetic energy exceeds MAX_KINETIC, hourglass energy
    MAX_HOURGLASS (fractions of the internal work) or energy error MAX_ENERGY_ERROR: the
    figure it gave is less trustworthy (a finer cell, or a slower pull or press)."""
    out = []
    for name, c in checks.items():
        for key, limit, what in (("kinetic_fraction", MAX_KINETIC, "kinetic energy"),
                                 ("hourglass_fraction", MAX_HOURGLASS, "hourglass energy"),
                                 ("energy_error", MAX_ENERGY_ERROR, "energy error")):
            if c[key] > limit:
                out.append(f"{name}: {what} {c[key]:.1%} of the internal work, above "
                           f"{limit:.0%} (a finer cell{' or a slower test' if key == 'kinetic_fraction' else ''})")
    return out


def calibrate_crossover(geometry_path, yarn_path, template_path, out: Path,
                        speed: float = 1.0) -> dict:
    """Run the virtual tests, write ``OUT/fabric.toml`` (the template with the cell's
    values), ``OUT/crossover_calibration.json`` (values, checks, round trip) and the
    figures ``OUT/compression.png``, ``OUT/extension.png``; returns the JSON's content."""
    from wovenimpact.spec import load_material
    from wovenimpact.spec.crossover import load_geometry

    geometry = load_geometry(geometry_path)
    yarn = load_material(yarn_path)
    template = Path(template_path).read_text(encoding="utf-8")
    compression = compress_cell(geometry, yarn, force=3.0, speed=speed, ends="thesis",
                                measure="yarns", max_time=2e-3)
    extension = extend_cell(geometry, yarn, strain=max(ROUND_TRIP_STRAINS), speed=speed)
    biaxial = extend_cell(geometry, yarn, strain=max(ROUND_TRIP_STRAINS), speed=speed,
                          ratio=1.0)
    head = (f"# Written by `wovenimpact calibrate crossover` from {Path(geometry_path).name} "
            f"(geometry) and\n# {Path(yarn_path).name} (yarn), over the template "
            f"{Path(template_path).name}: the lines marked with\n# their source come from "
            "the 3-D cell (docs/solid.md §6.6) or scale the template's yarn strength;\n# the "
            "shear law and the options are the template's (its header comments, which\n# "
            "name the sources of its own values, are left out).\n")
    values = cell_values(geometry, compression, extension,
                         load_material(template_path))
    values[("material", "name")] = (json.dumps(f"crossover cell {geometry.cell.name}"),
                                    "the geometry file's cell")
    text = head + set_values(drop_header(template), values)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fabric_path = out / "fabric.toml"
    atomic_write_text(fabric_path, text)
    params = load_material(fabric_path)  # the file must load as written
    shell = shell_tests(params, extension.length)
    rows = round_trip(shell, extension.length, compression, extension, biaxial)
    checks = {name: {"kinetic_fraction": r.kinetic_fraction,
                     "hourglass_fraction": r.hourglass_fraction,
                     "energy_error": r.energy_error, "steps": r.steps, "elements": r.elements}
              for name, r in (("compression", compression), ("extension", extension),
                              ("equibiaxial", biaxial))}
    doc = {
        "fabric_file": fabric_path.name,
        "e1_Pa": extension.e1, "nu": extension.nu, "a_m": compression.fit.a_m,
        "b_N": compression.fit.b_N, "fit_r2": compression.fit.r2,
        "checks": checks,
        "warnings": check_warnings(checks),
        "round_trip": rows,
    }
    atomic_write_text(out / "crossover_calibration.json", json.dumps(doc, indent=2) + "\n")
    _figures(out, compression, extension, biaxial, shell)
    return doc


def _figures(out: Path, compression, extension, biaxial, shell: dict[str, dict]) -> None:
    """compression.png (the cell's curve and the law) and extension.png (the cell's end
    forces and the written file's single-element tensions)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fit = compression.fit
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(compression.d * 1e3, compression.force, label="cell (yarns' contact force)")
    d = np.linspace(0.0, min(float(compression.d.max()), 0.999 * fit.a_m), 100)
    ax.plot(d * 1e3, fit.b_N * d / (fit.a_m - d), "--",
            label=f"F = b d/(a − d): a = {fit.a_m * 1e3:.4f} mm, b = {fit.b_N:.3f} N")
    _save(fig, ax, "compression d_c (mm)", "F_c (N)", out / "compression.png")
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    side = extension.length
    for test, run, style in (("uniaxial", extension, "C0"), ("biaxial", biaxial, "C1")):
        ax.plot(run.strain * 100, run.force, color=style, label=f"cell, {test}")
        h = shell[test]
        ax.plot(np.asarray(h["displacement_m"]) / side * 100, h["tension_w_N"], "--",
                color=style, label=f"shell single element, {test}")
    _save(fig, ax, "strain of the warp (%)", "warp end force / yarn tension (N)",
          out / "extension.png")


def _save(fig, ax, xlabel: str, ylabel: str, path: Path) -> None:
    """Axis labels, grid and legend; written to ``path`` and closed."""
    from wovenimpact.io.atomic import save_png

    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_png(fig, path, dpi=110)
