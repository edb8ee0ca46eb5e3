"""Material files (TOML) → validated SI parameter sets.

``[material] kind = "woven_fabric"`` gives :class:`~wovenimpact.materials.fabric.FabricParameters`
(docs/model.md §1, thesis Tables 5-1 and 7-2); ``kind = "j2_plastic"`` or ``"elastic"`` gives
:class:`~wovenimpact.materials.metal.MetalParameters` (docs/model.md §5, thesis Tables 7-1,
8-1, 8-2); ``kind = "transversely_isotropic"`` gives
:class:`~wovenimpact.materials.transverse_isotropic.TransverseIsotropicParameters`, the
material of solid sections (docs/solid.md §2, thesis Table 5-2). Every dimensioned value carries its unit (``"96 GPa"``) and is converted
to SI once, here. Unknown keys, missing units, wrong dimensions and unphysical
values are errors; all problems of a file are reported together in one
:class:`~wovenimpact.errors.InputError`, one line each::

    kevlar.toml: material.warp.crimp: must be ≥ 0 (got -0.01; valid: a dimensionless number ≥ 0 ...)

Suspicious but admissible inputs (a yarn area far from the lenticular section,
h0 inconsistent with the crimp) are reported as :class:`InputWarning`. A fabric without
crimp (a family's h0 = 0) and a compaction limit ``a`` at or above the crossover's height
h_w0 + h_f0 are errors (:func:`_check_weave_geometry`).

Geometry (thesis eq. 5.2, 5.5): the in-plane half-length of a family-i yarn
between crossings is ℓ_i0 = 1/(2 n_j), n_j the thread count of the CROSSING
family; h_i0 solves eq. (5.5) for ℓ_i0 and the crimp c_i unless given.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field, ValidationError

from wovenimpact.errors import InputError
from wovenimpact.kernels.fabric_layout import REG_ROWS_MAX
from wovenimpact.kernels.j2_layout import FRAC_ROWS_MAX, N_HARD_MAX
from wovenimpact.materials.crimp import crimp_amplitude, half_length_from_thread_count
from wovenimpact.materials.fabric import (
    FabricOptions,
    FabricParameters,
    FailureRegularisation,
    YarnFamily,
)
from wovenimpact.materials.metal import (
    DamageParameters,
    FractureRegularisation,
    MetalParameters,
    RateParameters,
)
from wovenimpact.materials.transverse_isotropic import TransverseIsotropicParameters
from wovenimpact.spec.fields import (
    STRICT,
    InputWarning,
    Problem,
    dotted,
    input_error,
    problems_from_validation,
    quantity,
    raise_problems,
    read_toml,
)

WIDTH_TOLERANCE = 1e-3  # width may exceed the yarn pitch by 0.1 %: rounding of printed tables
LENTICULAR_TOLERANCE = 0.05  # warn if A differs from (2/π)·width·thickness by more than 5 %
H0_TOLERANCE = 0.01  # warn if a given h0 differs from eq. (5.5) by more than 1 %
# bounds no real material passes (a unit slip, an extra exponent): stiffer than diamond
# (1.2 TPa), a fibre lighter than air or denser than osmium (22.6 g/cm³); crimps of
# woven fabrics are a few % (50 % would be a yarn half again as long as the fabric)
MAX_MODULUS = 2e12
MIN_DENSITY = 1.0
MAX_DENSITY = 1e5
MAX_CRIMP = 0.5
MAX_COMPACTION_FORCE = 1e6  # N: b of one crossover (Kevlar: 0.98 N)
MAX_YIELD_STRAIN = 0.1  # initial yield stress / modulus: metals yield below 1 %
MAX_PITCH_WIDTHS = 10.0  # yarns further apart than 10 widths are not a woven fabric
PLANE_STRESS_TRIAXIALITY = 2.0 / 3.0  # |η| = |σ_m / σ_eq| ≤ 2/3 in plane stress
MAX_RATE_RATIO = 1e8  # Johnson–Cook rate terms must stay positive up to ε̇/ε̇0 = 1e8

# --- woven fabric -------------------------------------------------------------------


class YarnSpec(BaseModel):
    """``[material.warp]`` / ``[material.fill]``: one yarn family."""

    model_config = STRICT
    thread_count: quantity("inverse_length", gt=0)  # threads per length of THIS family
    crimp: quantity("dimensionless", ge=0, le=MAX_CRIMP, example="0.0421")
    area: quantity("area", gt=0)
    modulus: quantity("pressure", gt=0, le=MAX_MODULUS, example="96 GPa")
    ultimate_tension: quantity("force", gt=0)
    width: quantity("length", gt=0, example="0.9407 mm")
    thickness: quantity("length", gt=0, example="0.2499 mm")
    # optional: the crimp amplitude given directly instead of computed from eq. (5.5)
    h0: quantity("length", ge=0, example="0.12495 mm") | None = None


class CompactionSpec(BaseModel):
    """``[material.compaction]``: F = b δ / (a − δ), thesis eq. (5.8)."""

    model_config = STRICT
    a: quantity("length", gt=0, example="0.12389 mm")
    b: quantity("force", gt=0, le=MAX_COMPACTION_FORCE, example="0.98432 N")


class ShearSpec(BaseModel):
    """``[material.shear]``: trellis moduli and compaction ratio (thesis 3.6.2, 6.2.7)."""

    model_config = STRICT
    g1: quantity("pressure", gt=0, example="0.0824 GPa")
    g2: quantity("pressure", gt=0, example="8.24 GPa")
    c_max: quantity("dimensionless", gt=0, le=1, example="0.65")


class OptionsSpec(BaseModel):
    """``[material.options]``: model variants (docs/model.md §1.4–1.7)."""

    model_config = STRICT
    homogenisation: Literal["virial", "thesis"] = "virial"
    shear: Literal["true", "thesis"] = "true"
    frame: Literal["fibre", "green-naghdi"] = "fibre"
    failure: Literal["instant", "progressive"] = "instant"
    softening_strain: quantity("dimensionless", gt=0, example="0.01") | None = None
    # erode a point once a broken yarn family is stretched past this on an element of the
    # reference length, i.e. opened by (this − 1) × reference length on any (0: never)
    erode_broken_stretch: quantity("dimensionless", ge=0, example="2.0") = 2.0
    # ... or, with a family broken, either family crushed below this (0: never; < 1)
    erode_broken_crush: quantity("dimensionless", ge=0, lt=1, example="0.5") = 0.5
    # ... and, intact or not, once λ_w λ_f falls below this (0: never, the default; < 1)
    erode_intact_crush: quantity("dimensionless", ge=0, lt=1, example="0.1") = 0.0
    # crossover evaluation (docs/theory.md §1.9): tabulated stored energy or exact solve
    crossover: Literal["table", "exact"] = FabricOptions.crossover


ScaleTable = list[
    tuple[
        quantity("dimensionless", gt=0, example="4"),
        quantity("dimensionless", gt=0, le=100, example="0.8"),
    ]
]


class FabricRegularisationSpec(BaseModel):
    """``[material.regularisation]``: element-size regularisation of yarn failure
    (docs/theory.md §1.4; :class:`~wovenimpact.materials.fabric.FailureRegularisation`)."""

    model_config = STRICT
    # h_ref; default: the crossover cell along each family, 2ℓ_i0
    reference_length: quantity("length", gt=0, example="0.94 mm") | None = None
    # [[h/h_ref, scale of T_u], ...], h/h_ref increasing, scale 1 at h/h_ref = 1
    strength_scale: ScaleTable = Field(default_factory=list, max_length=REG_ROWS_MAX)
    softening_opening: quantity("length", gt=0, example="0.3 mm") | None = None
    erosion_opening: quantity("length", gt=0, example="0.94 mm") | None = None


class FabricSpec(BaseModel):
    """``[material]`` with ``kind = "woven_fabric"``."""

    model_config = STRICT
    name: str = Field(min_length=1)
    kind: Literal["woven_fabric"]
    fibre_density: quantity("density", ge=MIN_DENSITY, le=MAX_DENSITY, example="1.44 g/cm^3")
    areal_density: quantity("areal_density", gt=0, example="0.477 kg/m^2") | None = None
    thickness: quantity("length", gt=0, example="0.4998 mm") | None = None
    warp: YarnSpec
    fill: YarnSpec
    compaction: CompactionSpec
    shear: ShearSpec
    options: OptionsSpec = OptionsSpec()
    regularisation: FabricRegularisationSpec | None = None


class FabricFile(BaseModel):
    model_config = STRICT
    material: FabricSpec


# --- metals --------------------------------------------------------------------------


class PlasticitySpec(BaseModel):
    """``[material.plasticity]``: hardening table [[ε_p, σ_y], ...] and fracture strain."""

    model_config = STRICT
    hardening: list[
        tuple[
            quantity("dimensionless", ge=0, example="0.18"),
            quantity("pressure", gt=0, example="213.78 MPa"),
        ]
    ] = Field(min_length=1)
    fracture_strain: quantity("dimensionless", gt=0, example="0.18") | None = None


class RateSpec(BaseModel):
    """``[material.rate]``: Johnson–Cook rate factor 1 + C ln(ε̇p/ε̇0) for ε̇p > ε̇0."""

    model_config = STRICT
    c: quantity("dimensionless", ge=0, example="0.014")
    reference_rate: quantity("strain_rate", gt=0, example="1 1/s")


class DamageSpec(BaseModel):
    """``[material.damage]``: Johnson–Cook fracture strain
    ε_f = (d1 + d2 exp(d3 η))(1 + d4 ln ε̇*)(1 + d5 T*), T* = 0 (temperature not modelled)."""

    model_config = STRICT
    d1: quantity("dimensionless", example="-0.09")
    d2: quantity("dimensionless", example="0.25")
    d3: quantity("dimensionless", example="-0.5")
    d4: quantity("dimensionless", example="0.014")
    d5: quantity("dimensionless", example="3.87") = 0.0
    # ε̇0 of the rate term; default: [material.rate] reference_rate
    reference_rate: quantity("strain_rate", gt=0, example="1 1/s") | None = None


class MetalRegularisationSpec(BaseModel):
    """``[material.regularisation]``: element-size regularisation of fracture
    (docs/theory.md §7.3; :class:`~wovenimpact.materials.metal.FractureRegularisation`)."""

    model_config = STRICT
    # needed by fracture_scale and failure_displacement (not by hinge_ratio)
    reference_length: quantity("length", gt=0, example="0.5 mm") | None = None
    # [[l_e/l_ref, scale of the fracture strain], ...], l_e/l_ref increasing, 1 at 1
    fracture_scale: ScaleTable = Field(default_factory=list, max_length=FRAC_ROWS_MAX)
    failure_displacement: quantity("length", gt=0, example="0.05 mm") | None = None
    # l_h/t, the width of a fold in the section's thicknesses: theory §7.3, "Folds"
    hinge_ratio: quantity("dimensionless", gt=0, example="1") | None = None


class J2Spec(BaseModel):
    """``[material]`` with ``kind = "j2_plastic"`` (aluminium casing, titanium blade)."""

    model_config = STRICT
    name: str = Field(min_length=1)
    kind: Literal["j2_plastic"]
    density: quantity("density", gt=0, example="2.78 g/cm^3")
    modulus: quantity("pressure", gt=0, le=MAX_MODULUS, example="72 GPa")
    poisson: quantity("dimensionless", ge=0, lt=0.5, example="0.3")
    plasticity: PlasticitySpec
    rate: RateSpec | None = None
    damage: DamageSpec | None = None
    regularisation: MetalRegularisationSpec | None = None


class ElasticSpec(BaseModel):
    """``[material]`` with ``kind = "elastic"`` (steel impactor when deformable)."""

    model_config = STRICT
    name: str = Field(min_length=1)
    kind: Literal["elastic"]
    density: quantity("density", gt=0, example="2.78 g/cm^3")
    modulus: quantity("pressure", gt=0, le=MAX_MODULUS, example="72 GPa")
    poisson: quantity("dimensionless", ge=0, lt=0.5, example="0.3")


class TransverseIsotropicSpec(BaseModel):
    """``[material]`` with ``kind = "transversely_isotropic"``: a linear elastic solid
    stiff along its fibre axis a1 (the yarn of the 3-D crossover, thesis Table 5-2), for
    solid sections (docs/solid.md §2)."""

    model_config = STRICT
    name: str = Field(min_length=1)
    kind: Literal["transversely_isotropic"]
    density: quantity("density", ge=MIN_DENSITY, le=MAX_DENSITY, example="1.44 g/cm^3")
    # along the fibre axis a1
    e11: quantity("pressure", gt=0, le=MAX_MODULUS, example="96 GPa")
    # across it (E22 = E33)
    e22: quantity("pressure", gt=0, le=MAX_MODULUS, example="3.28 GPa")
    # axial shear modulus G12 = G13
    g12: quantity("pressure", gt=0, le=MAX_MODULUS, example="3.28 GPa")
    # transverse shear modulus; not given: E22 / (2 (1 + ν23)), isotropic across the fibre
    g23: quantity("pressure", gt=0, le=MAX_MODULUS, example="3.28 GPa") | None = None
    # ν12 = ν13: lateral strain −ν12 ε under a stress along a1; with ν23 it must leave the
    # stiffness positive definite, |ν12| < √((1 − ν23) E11 / (2 E22))
    nu12: quantity("dimensionless", example="0")
    # ν23, in the plane across the fibre
    nu23: quantity("dimensionless", gt=-1, lt=1, example="0")


class TransverseIsotropicFile(BaseModel):
    model_config = STRICT
    material: TransverseIsotropicSpec


class J2File(BaseModel):
    model_config = STRICT
    material: J2Spec


class ElasticFile(BaseModel):
    model_config = STRICT
    material: ElasticSpec


_FILE_MODELS: dict[str, type[BaseModel]] = {
    "woven_fabric": FabricFile,
    "j2_plastic": J2File,
    "elastic": ElasticFile,
    "transversely_isotropic": TransverseIsotropicFile,
}

# --- loading -------------------------------------------------------------------------


def load_material(
    path: str | Path,
) -> FabricParameters | MetalParameters | TransverseIsotropicParameters:
    """Read a material TOML file and return its validated SI parameters.

    Raises:
        InputError: unreadable file, invalid TOML, or any invalid entry (all listed).
    """
    path = Path(path)
    return material_from_dict(read_toml(path, "material file"), source=str(path))


def material_from_dict(
    d: dict[str, Any], source: str = "<dict>", *, collect_warnings: list[str] | None = None
) -> FabricParameters | MetalParameters | TransverseIsotropicParameters:
    """Validate a parsed material document ``{"material": {...}}`` and convert it to SI.

    Args:
        d: the document as read from TOML (top-level key ``material``).
        source: file name used at the start of every message.
        collect_warnings: if given, warnings are appended here instead of being
            issued with :func:`warnings.warn` (category :class:`InputWarning`).
    """
    table = d.get("material") if isinstance(d, dict) else None
    kind = table.get("kind") if isinstance(table, dict) else None
    if not isinstance(kind, str) or kind not in _FILE_MODELS:
        valid = ", ".join(repr(k) for k in _FILE_MODELS)
        if not isinstance(table, dict):
            problem = Problem("material", "is missing or not a table", valid="a [material] table")
        elif kind is None:
            problem = Problem("material.kind", "is missing", valid=valid)
        else:
            problem = Problem("material.kind", "is not a known material kind", kind, valid)
        raise input_error([problem], source)
    file_model = _FILE_MODELS[kind]
    try:
        spec = file_model.model_validate(d).material
    except ValidationError as err:
        raise input_error(problems_from_validation(err, file_model), source) from None
    notes: list[str] = []
    if isinstance(spec, FabricSpec):
        result = _fabric_parameters(spec, table, source, notes)
    elif isinstance(spec, TransverseIsotropicSpec):
        result = _transverse_isotropic_parameters(spec, source)
    else:
        result = _metal_parameters(spec, table, source)
    for note in notes:
        if collect_warnings is not None:
            collect_warnings.append(note)
        else:
            warnings.warn(note, InputWarning, stacklevel=2)
    return result


def _transverse_isotropic_parameters(spec: TransverseIsotropicSpec,
                                     source: str) -> TransverseIsotropicParameters:
    """The SI parameters; a stiffness that is not positive definite is an InputError
    naming the file and the constant."""
    g23 = spec.g23 if spec.g23 is not None else spec.e22 / (2.0 * (1.0 + spec.nu23))
    try:
        return TransverseIsotropicParameters(
            e11=spec.e11, e22=spec.e22, g12=spec.g12, g23=g23, nu12=spec.nu12,
            nu23=spec.nu23, density=spec.density, name=spec.name)
    except InputError as err:
        raise InputError(f"{source}: {err}") from None


def _raw(table: dict, *keys: str | int) -> Any:
    value: Any = table
    for k in keys:
        value = value[k]
    return value


def _fabric_parameters(
    spec: FabricSpec, raw: dict, source: str, notes: list[str]
) -> FabricParameters:
    problems = _check_fabric(spec, raw)
    raise_problems(problems, source)
    # ℓ_i0 = 1/(2 n_j): half-length of family i between crossings of family j (eq. 5.2).
    half = {
        "warp": half_length_from_thread_count(spec.fill.thread_count),
        "fill": half_length_from_thread_count(spec.warp.thread_count),
    }
    families = {}
    for fam in ("warp", "fill"):
        y: YarnSpec = getattr(spec, fam)
        h0_eq55 = crimp_amplitude(half[fam], y.crimp)
        h0 = h0_eq55 if y.h0 is None else y.h0
        if y.h0 is not None and abs(h0 - h0_eq55) > H0_TOLERANCE * max(h0_eq55, 1e-300):
            notes.append(
                f"{source}: material.{fam}.h0: {_raw(raw, fam, 'h0')!r} differs by more than "
                f"{H0_TOLERANCE:.0%} from the amplitude {h0_eq55 * 1e3:.5f} mm of eq. (5.5) for "
                f"crimp {y.crimp:g}; the given h0 is used (the crimp still sets the areal mass)"
            )
        lenticular = 2.0 / math.pi * y.width * y.thickness
        if abs(y.area - lenticular) > LENTICULAR_TOLERANCE * lenticular:
            notes.append(
                f"{source}: material.{fam}.area: {y.area * 1e6:.6g} mm^2 differs by more than "
                f"{LENTICULAR_TOLERANCE:.0%} from the lenticular section (2/π)·width·thickness = "
                f"{lenticular * 1e6:.6g} mm^2 (docs/model.md §1.1): check area, width and thickness"
            )
        families[fam] = YarnFamily(
            half_length=half[fam],
            crimp=y.crimp,
            h0=h0,
            area=y.area,
            modulus=y.modulus,
            ultimate_tension=y.ultimate_tension,
            width=y.width,
            thickness=y.thickness,
        )
    o = spec.options
    if o.failure == "instant" and o.softening_strain is not None:
        notes.append(
            f"{source}: material.options.softening_strain is ignored with failure = 'instant' "
            "(set failure = 'progressive' to use it)"
        )
    options = FabricOptions(
        homogenisation=o.homogenisation,
        shear=o.shear,
        frame=o.frame,
        failure=o.failure,
        softening_strain=o.softening_strain if o.failure == "progressive" else 0.0,
        erode_broken_stretch=o.erode_broken_stretch,
        erode_broken_crush=o.erode_broken_crush,
        erode_intact_crush=o.erode_intact_crush,
        crossover=o.crossover,
    )
    r = spec.regularisation
    regularisation = FailureRegularisation() if r is None else FailureRegularisation(
        reference_length=r.reference_length,
        strength_scale=tuple((float(x), float(v)) for x, v in r.strength_scale),
        softening_opening=r.softening_opening or 0.0,
        erosion_opening=r.erosion_opening or 0.0,
    )
    return FabricParameters(
        warp=families["warp"],
        fill=families["fill"],
        compaction_a=spec.compaction.a,
        compaction_b=spec.compaction.b,
        shear_g1=spec.shear.g1,
        shear_g2=spec.shear.g2,
        shear_c_max=spec.shear.c_max,
        fibre_density=spec.fibre_density,
        areal_density=spec.areal_density,
        thickness=spec.thickness,
        options=options,
        regularisation=regularisation,
        name=spec.name,
    )


def _check_fabric(spec: FabricSpec, raw: dict) -> list[Problem]:
    """Rules that involve several fields (single-field bounds are in the schema)."""
    problems = []
    if spec.shear.g2 < spec.shear.g1:
        problems.append(
            Problem(
                "material.shear.g2",
                "is smaller than g1 (the modulus at full compaction cannot be below the "
                "initial one)",
                _raw(raw, "shear", "g2"),
                f"a pressure ≥ g1 = {_raw(raw, 'shear', 'g1')!r}",
            )
        )
    for fam, other in (("warp", "fill"), ("fill", "warp")):
        y: YarnSpec = getattr(spec, fam)
        pitch = 1.0 / y.thread_count  # spacing of parallel family-i yarns = 2 ℓ_j0
        if y.width > pitch * (1.0 + WIDTH_TOLERANCE):
            problems.append(
                Problem(
                    f"material.{fam}.width",
                    f"is wider than the spacing of parallel {fam} yarns, 1/thread_count = "
                    f"2ℓ_{other}0 = {pitch * 1e3:.6g} mm, by more than the "
                    f"{WIDTH_TOLERANCE:.1%} allowed for rounding in printed tables",
                    _raw(raw, fam, "width"),
                    f"a length ≤ {pitch * (1.0 + WIDTH_TOLERANCE) * 1e3:.6g} mm",
                )
            )
    problems += _check_weave_geometry(spec, raw)
    r = spec.regularisation
    opening = r is not None and r.softening_opening is not None
    if spec.options.failure == "progressive" and spec.options.softening_strain is None \
            and not opening:
        problems.append(
            Problem(
                "material.options.softening_strain",
                "is required when failure = 'progressive' (the strain over which the yarn "
                "tension falls to zero, docs/theory.md §1.4), unless "
                "material.regularisation.softening_opening gives the softening as an opening",
                valid="a dimensionless number > 0 such as 0.01",
            )
        )
    if opening and spec.options.failure != "progressive":
        problems.append(Problem(
            "material.regularisation.softening_opening",
            "needs material.options.failure = 'progressive' (an instant failure has no "
            "softening)", _raw(raw, "regularisation", "softening_opening"),
            "failure = 'progressive', or no softening_opening"))
    if opening and spec.options.softening_strain is not None:
        problems.append(Problem(
            "material.options.softening_strain",
            "and material.regularisation.softening_opening both give the softening; the "
            "opening takes the element's length into account, the strain does not",
            _raw(raw, "options", "softening_strain"), "one of the two"))
    if r is not None:
        problems += _check_scale_table(r.strength_scale, raw, "strength_scale")
    return problems


def _check_scale_table(table: list[tuple[float, float]], raw: dict, key: str) -> list[Problem]:
    """A regularisation table: lengths strictly increasing, the scale 1 at the reference
    length (where the material's own value holds, docs/theory.md §1.4, §7.3)."""
    if not table:
        return []
    loc = f"material.regularisation.{key}"
    xs = [float(x) for x, _ in table]
    if any(b <= a for a, b in zip(xs, xs[1:])):
        return [Problem(loc, "has lengths (first column, element length / reference length) "
                        "that do not strictly increase", _raw(raw, "regularisation", key),
                        "rows [[l/l_ref, scale], ...] with l/l_ref strictly increasing")]
    at_one = float(np.interp(1.0, xs, [float(v) for _, v in table]))
    if abs(at_one - 1.0) > 1e-12:
        return [Problem(loc, f"gives the scale {at_one:.6g} at the reference length (l/l_ref "
                        "= 1), where the material's own value must hold",
                        _raw(raw, "regularisation", key),
                        "a table whose scale is 1 at l/l_ref = 1 (e.g. a row [1, 1])")]
    return []


def _check_weave_geometry(spec: FabricSpec, raw: dict) -> list[Problem]:
    """A weave the crossover cell can hold (theory: material geometry, docs/inputs.md):
    each yarn fits in its width × thickness box and is no thicker than wide, yarns lie
    at most MAX_PITCH_WIDTHS widths apart, each family is crimped (h0 > 0), the two crimp
    heights (eq. 5.5, or h0 given) add up to at most the two yarn thicknesses (Peirce:
    about half of them), and the compaction limit a is below the crossover's height
    h_w0 + h_f0 (theory §1.3: H_w + H_f = h_w0 + h_f0 − δ with δ < a)."""
    problems = []
    t_sum = spec.warp.thickness + spec.fill.thickness
    heights = 0.0
    straight = False
    for fam, other in (("warp", "fill"), ("fill", "warp")):
        y: YarnSpec = getattr(spec, fam)
        pitch = 1.0 / y.thread_count
        if y.area > y.width * y.thickness:
            problems.append(Problem(
                f"material.{fam}.area", "is larger than the yarn's width × thickness box "
                f"({y.width * y.thickness * 1e6:.4g} mm^2)", _raw(raw, fam, "area"),
                f"an area ≤ width × thickness; a lenticular yarn has (2/π)·width·thickness = "
                f"{2 / math.pi * y.width * y.thickness * 1e6:.4g} mm^2"))
        if y.thickness > y.width:
            problems.append(Problem(
                f"material.{fam}.thickness", f"is larger than the yarn width "
                f"({y.width * 1e3:.4g} mm): a yarn is flattened by weaving, not upright",
                _raw(raw, fam, "thickness"), f"a length ≤ width = {y.width * 1e3:.4g} mm"))
        if pitch > MAX_PITCH_WIDTHS * y.width:
            problems.append(Problem(
                f"material.{fam}.thread_count", f"puts the {fam} yarns {pitch * 1e3:.4g} mm "
                f"apart, more than {MAX_PITCH_WIDTHS:g} yarn widths: an open net, not a woven "
                "fabric", _raw(raw, fam, "thread_count"),
                f"a thread count ≥ {1.0 / (MAX_PITCH_WIDTHS * y.width) * 0.0254:.4g} 1/in"))
        half = half_length_from_thread_count(getattr(spec, other).thread_count)
        h0 = crimp_amplitude(half, y.crimp) if y.h0 is None else y.h0
        heights += h0
        if h0 == 0.0:
            straight = True
            key = "crimp" if y.h0 is None else "h0"
            problems.append(Problem(
                f"material.{fam}.{key}", f"is 0: a straight {fam} yarn (h0 = 0), outside the "
                "crossover model, whose yarns undulate round each other (eq. 5.5): its table "
                "measures heights against h0 (docs/theory.md §1.9) and the compaction limit "
                "a must lie below h_w0 + h_f0", _raw(raw, fam, key),
                f"a crimp > 0 and ≤ {MAX_CRIMP:g} such as 0.0421; woven fabrics have a few %, "
                "a nearly straight family e.g. 0.001" if key == "crimp" else
                "a length > 0 such as '0.12495 mm', or no h0 (eq. 5.5 from the crimp)"))
    if heights > t_sum:
        problems.append(Problem(
            "material.warp.crimp / material.fill.crimp (or h0)",
            f"give crimp heights h_w0 + h_f0 = {heights * 1e3:.4g} mm (eq. 5.5), more than the "
            f"two yarn thicknesses {t_sum * 1e3:.4g} mm: the yarns cannot undulate that far "
            "around each other", {"warp": _raw(raw, "warp", "crimp"),
                                  "fill": _raw(raw, "fill", "crimp")},
            f"crimps whose heights add up to at most {t_sum * 1e3:.4g} mm (Peirce's geometry: "
            f"about half, {t_sum * 0.5e3:.4g} mm; woven fabrics have crimps of a few %)"))
    if not straight and spec.compaction.a >= heights:
        # δ(F) = a F/(b + F) → a: with a ≥ h_w0 + h_f0 a finite push would flatten the
        # crossover to nothing (H_w + H_f = 0) and the law beyond it means nothing
        problems.append(Problem(
            "material.compaction.a", f"is not below the crossover's height h_w0 + h_f0 = "
            f"{heights * 1e3:.5g} mm (eq. 5.5, or h0 given): the law F = b δ/(a − δ) presses "
            "the yarns into each other by δ < a, and H_w + H_f = h_w0 + h_f0 − δ must stay "
            "above 0 (docs/theory.md §1.3)", _raw(raw, "compaction", "a"),
            f"a length < {heights * 1e3:.5g} mm; the thesis's Kevlar has a = 0.12389 mm, "
            "about half its h_w0 + h_f0"))
    return problems


def _metal_parameters(spec: J2Spec | ElasticSpec, raw: dict, source: str) -> MetalParameters:
    hardening: tuple[tuple[float, float], ...] = ()
    fracture = None
    rate = damage = None
    if isinstance(spec, J2Spec):
        table = spec.plasticity.hardening
        reg_problems = []
        if spec.regularisation is not None:
            reg_problems = _check_scale_table(spec.regularisation.fracture_scale, raw,
                                              "fracture_scale")
            if spec.plasticity.fracture_strain is None and spec.damage is None:
                reg_problems.append(Problem(
                    "material.regularisation", "regularises a fracture strain the material "
                    "does not have", valid="material.plasticity.fracture_strain or a "
                    "[material.damage] table, or no [material.regularisation]"))
            r = spec.regularisation
            if r.reference_length is None and (r.fracture_scale or r.failure_displacement):
                reg_problems.append(Problem(
                    "material.regularisation.reference_length", "is missing",
                    valid="the element length at which the fracture strain holds as given "
                    "(fracture_scale and failure_displacement are relative to it)"))
            if (spec.regularisation.hinge_ratio is not None
                    and spec.plasticity.fracture_strain is not None and spec.damage is not None):
                reg_problems.append(Problem(
                    "material.regularisation.hinge_ratio", "needs one fracture criterion, "
                    "the material has two (plasticity.fracture_strain and [material.damage])",
                    _raw(raw, "regularisation", "hinge_ratio"),
                    "a hinge ratio with either fracture_strain or [material.damage]"))
        raise_problems(_check_hardening(table, raw) + _check_damage(spec, raw)
                       + _check_yield_strain(spec, raw) + reg_problems, source)
        hardening = tuple((float(e), float(s)) for e, s in table)
        fracture = spec.plasticity.fracture_strain
        if spec.rate is not None:
            rate = RateParameters(c=spec.rate.c, reference_rate=spec.rate.reference_rate)
        if spec.damage is not None:
            d = spec.damage
            ref = d.reference_rate
            if ref is None:
                ref = spec.rate.reference_rate if spec.rate is not None else 1.0
            damage = DamageParameters(d=(d.d1, d.d2, d.d3, d.d4, d.d5), reference_rate=ref)
    regularisation = None
    r = getattr(spec, "regularisation", None)
    if r is not None:
        regularisation = FractureRegularisation(
            reference_length=r.reference_length or 0.0,
            fracture_scale=tuple((float(x), float(v)) for x, v in r.fracture_scale),
            failure_displacement=r.failure_displacement or 0.0,
            hinge_ratio=r.hinge_ratio or 0.0,
        )
    return MetalParameters(
        name=spec.name,
        kind=spec.kind,
        density=spec.density,
        modulus=spec.modulus,
        poisson=spec.poisson,
        hardening=hardening,
        fracture_strain=fracture,
        rate=rate,
        damage=damage,
        regularisation=regularisation,
    )


def _check_damage(spec: J2Spec, raw: dict) -> list[Problem]:
    """Johnson–Cook damage: ε_f > 0 over the plane-stress triaxialities and rates."""
    d = spec.damage
    if d is None:
        return []
    problems = []
    for eta in (-PLANE_STRESS_TRIAXIALITY, PLANE_STRESS_TRIAXIALITY):
        ef = d.d1 + d.d2 * math.exp(d.d3 * eta)
        if not ef > 0.0:
            problems.append(
                Problem(
                    "material.damage",
                    f"gives a fracture strain d1 + d2 exp(d3 η) = {ef:.4g} ≤ 0 at triaxiality "
                    f"η = {eta:+.4g} (plane stress reaches |η| = 2/3)",
                    {k: _raw(raw, "damage", k) for k in ("d1", "d2", "d3")},
                    "d1, d2, d3 with d1 + d2 exp(d3 η) > 0 for -2/3 ≤ η ≤ 2/3",
                )
            )
            break
    if 1.0 + d.d4 * math.log(MAX_RATE_RATIO) <= 0.0:
        problems.append(
            Problem(
                "material.damage.d4",
                f"makes the rate term 1 + d4 ln(ε̇/ε̇0) ≤ 0 below ε̇/ε̇0 = {MAX_RATE_RATIO:g}",
                _raw(raw, "damage", "d4"),
                f"a number > {-1.0 / math.log(MAX_RATE_RATIO):.4g}",
            )
        )
    if d.d4 != 0.0 and d.reference_rate is None and spec.rate is None:
        problems.append(
            Problem(
                "material.damage.reference_rate",
                "is required when d4 ≠ 0 and there is no [material.rate] table to take it from",
                valid="a strain rate > 0 such as '1 1/s'",
            )
        )
    return problems


def _check_yield_strain(spec: J2Spec, raw: dict) -> list[Problem]:
    """The initial yield strain σ_y0 / E at most MAX_YIELD_STRAIN (a stress in the
    wrong unit, or a modulus too small by orders)."""
    sy0 = spec.plasticity.hardening[0][1]
    if sy0 <= MAX_YIELD_STRAIN * spec.modulus:
        return []
    return [Problem("material.plasticity.hardening[0][1]", f"gives a yield strain σ_y0/E = "
                    f"{sy0 / spec.modulus:.3g} (modulus {spec.modulus:.3g} Pa)",
                    _raw(raw, "plasticity", "hardening")[0][1],
                    f"a yield stress ≤ {MAX_YIELD_STRAIN:g} E = "
                    f"{MAX_YIELD_STRAIN * spec.modulus / 1e6:.4g} MPa (metals yield below 1 %)")]


def _check_hardening(table: list[tuple[float, float]], raw: dict) -> list[Problem]:
    """ε_p starts at 0 and strictly increases; σ_y never decreases; at most N_HARD_MAX rows."""
    loc = ("material", "plasticity", "hardening")
    rows = _raw(raw, "plasticity", "hardening")
    problems = []
    if len(table) > N_HARD_MAX:
        problems.append(
            Problem(dotted(loc), f"has {len(table)} rows, more than the kernel's {N_HARD_MAX}",
                    f"{len(table)} rows", f"at most {N_HARD_MAX} rows")
        )
    if table[0][0] != 0.0:
        problems.append(
            Problem(dotted((*loc, 0, 0)), "must be 0 (the table starts at yield)", rows[0][0], "0")
        )
    for i in range(1, len(table)):
        if not table[i][0] > table[i - 1][0]:
            problems.append(
                Problem(
                    dotted((*loc, i, 0)),
                    "plastic strains must strictly increase down the table",
                    rows[i][0],
                    f"> {rows[i - 1][0]!r}",
                )
            )
        if table[i][1] < table[i - 1][1]:
            problems.append(
                Problem(
                    dotted((*loc, i, 1)),
                    "yield stresses must not decrease down the table (no softening)",
                    rows[i][1],
                    f"≥ {rows[i - 1][1]!r}",
                )
            )
    return problems
