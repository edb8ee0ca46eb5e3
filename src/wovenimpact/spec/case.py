"""Case files (TOML) → a validated :class:`CaseSpec` with every quantity in SI.

A case says what to simulate: materials (by file), shell sections, the mesh (a
generated plate or an Abaqus ``.inp``), constraints, initial velocities, body
force and the run controls. Every dimensioned value carries its unit; unknown
keys, missing units, wrong dimensions and out-of-range values are reported
together, one line each, naming the key::

    plate.toml: run.end_time: has no unit (got '200'; valid: a time > 0 such as '60 us')

TOML's types are kept: a count, a switch or a direction takes an integer, ``true`` /
``false`` or three numbers, and a string ``"4"``, a ``1`` for ``true`` or ``["1", "0",
"0"]`` is an error naming the type given (``spec.fields.integer``, ``boolean``,
``vector``). A generated mesh of more than LARGE_MESH elements needs
``run.allow_large_mesh = true``.

Two things are warnings (:class:`~wovenimpact.errors.InputWarning`), not errors: an
output interval longer than ``run.end_time`` (clipped to it, so that a run shortened
with ``--set run.end_time=…`` just runs) and a quarter plate whose ``symmetry_x`` /
``symmetry_y`` node sets no boundary constrains.

Schema (see README and examples/cases/)::

    [case]            name, description
    [materials]       NAME = "path/to/material.toml"   (relative to the case file), or
                      NAME = { file = "...", set = { warp = { crimp = "0.06" } } }
    [sections.NAME]   material, thickness?, bending_modulus?, bending_poisson?,
                      transverse_shear_modulus?, shear_factor?, hourglass?, areal_mass?,
                      points? (1: resultant section; odd n ≥ 3: n Simpson points),
                      membrane? ("full": 2×2 in-plane points, fabric default;
                      "reduced": one point + hourglass springs, metal default)
    [solid_sections.NAME]  material (transversely_isotropic), hourglass?,
                      fibre_direction?, second_direction? (8-node hexahedra, docs/solid.md)
    [mesh]            kind = "plate": side, width? (a rectangle: side along x, width
                      along y), element_size, plies, spacing, quarter,
                      section, warp_direction   | kind = "abaqus" | "gmsh" | "lsdyna": file,
                      sections = {ELSET = SECTION}, length_unit?, warp_direction?
                      (vector | "circumferential"), axis?, [mesh.containment]? (blade,
                      root, release, fragment, casing_layers: the file's sets of a
                      casing and fan blade of the user's own geometry)
                      | kind = "containment": element_size, [mesh.casing] (inner_radius,
                      length, sector, centre_angle, fine_sector, coarse_element_size,
                      inner_section, layer_section, layers, layer_spacing,
                      offset_layers), [mesh.blade] (section, root/crack/tip_radius,
                      root/tip_chord, angle, stagger, twist, tip_curve, element_size:
                      the blade's own, default mesh.element_size)
                      | kind = "block": size, elements, origin?, section (a box of
                      hexahedra; an imported mesh's C3D8R / C3D8 elements are solids too)
                      | kind = "crossover": file (a geometry file), warp_section,
                      fill_section? (the crossover cell of hexahedra, docs/solid.md §5)
    [[boundary]]      nodes = SET, type = clamped | pinned | symmetry_x | symmetry_y |
                      symmetry_z | velocity (with dof and velocity)
    [spin]            rate, release_time, relaxation_tolerance (containment cases)
    [amplitude]       ramp_time (smooth step of prescribed velocities, thesis Fig. 8-3)
    [[initial_velocity]]  nodes = SET, velocity = [vx, vy, vz] and/or
                      angular_velocity = [wx, wy, wz] about centre; optional radius
                      (only nodes within it of centre)
    [body_force]      acceleration = [ax, ay, az]
    [impactor]        shape = sphere | cylinder, radius, length, nose, nose_length, fillet,
                      density | mass, position (nose tip), direction, velocity,
                      axis? (⟂ direction: the body flies sideways, e.g. a cylinder's
                      side as an edge; default along the direction, nose first),
                      contact_stiffness (penalty factor β of k = β m / Δt²; 0.3),
                      contact_damping (ζ, fraction of critical; 1), friction (μ; 0)
    [[rigid_plane]]   point, normal (toward the nodes it meets), velocity? (prescribed;
                      default at rest: it holds), nodes? (default all), name?,
                      contact_stiffness (β; 0.3), contact_damping (ζ; 1), friction (μ; 0):
                      a rigid plate that presses or holds (docs/solid.md §6)
    [contact]         shell–shell contact: surfaces = plies | parts | element_sets |
                      none, self_contact, penalty_scale (β; 0.1), damping (ζ; 0.3),
                      damping_mode (always | approach), friction (μ; 0)
    [[initial_erosion]]  centre, radius, plies?: elements eroded at t = 0 (a hole: centroid
                      within radius of the axis through centre along cylinder_axis)
    [run]             end_time, field_interval, history_interval, checkpoint_interval,
                      alpha, erode_dt_fraction, erode_inverted, eroded_nodes (remove |
                      keep), mass_scaling_fraction, max_added_mass_fraction, threads,
                      max_steps (the
                      predicted step count end_time/Δt₁ above which the run is refused;
                      5e6; docs/inputs.md), allow_large_mesh (a mesh above LARGE_MESH
                      elements is refused without it)
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from wovenimpact.errors import InputWarning
from wovenimpact.impactor import BODY_PENALTY_SCALE, SIDEWAYS_COS
from wovenimpact.kernels.shell_layout import KINEMATIC_FRACTION
from wovenimpact.spec.fields import (
    STRICT,
    Problem,
    apply_overrides,
    boolean,
    check_numbers,
    input_error,
    integer,
    problems_from_validation,
    quantity,
    read_toml,
    toml_type,
    type_error,
    vector,
)

def _unit_direction(v: tuple[float, float, float]) -> tuple[float, float, float]:
    """A direction: three finite numbers, not all zero (it is normalised where used)."""
    if not all(math.isfinite(c) for c in v):
        raise ValueError(f"must be three finite numbers, got {list(v)}")
    if not any(c != 0.0 for c in v):
        raise ValueError("must be a non-zero vector")
    return v


DIRECTION_VALID = "three numbers, not all zero, such as [0, 0, -1], not quoted"
# an array of three TOML numbers: ["1", "0", "0"] or [true, 0, 0] is refused, not read
Direction = Annotated[vector(DIRECTION_VALID), AfterValidator(_unit_direction)]
Length = quantity("length", gt=0, example="0.94 mm")
Time = quantity("time", gt=0, example="10 us")
Velocity = quantity("velocity", example="-120 m/s")
Spin = quantity("angular_velocity", example="1047 rad/s")
Accel = quantity("acceleration", example="-9.81 m/s^2")
Coordinate = quantity("length", example="0 mm")
DOFS = ("ux", "uy", "uz", "rx", "ry", "rz")
# the axis normal to the plane of each symmetry boundary type ([[boundary]] type)
SYMMETRY_AXIS = {"symmetry_x": 0, "symmetry_y": 1, "symmetry_z": 2}
# run.max_steps default: a long casing run (5 ms of 0.5 mm elements at Δt ≈ 5e-8 s is 1e5
# steps) with 50× to spare; a run of 5e6 steps of 10⁵ elements is days on two cores
DEFAULT_MAX_STEPS = 5_000_000
# the largest mesh compiled: 5 million elements (the element and material state alone
# are ~10 GB); a larger count is a unit slip (mesh.side = "1e30 mm"), not a model
MAX_ELEMENTS = 5_000_000
# the largest mesh built without run.allow_large_mesh = true: on two cores 941 000 fabric
# elements (0.05 mm on examples/plate_impact/plies1_100.toml) took 21 s and 3.5 GB to
# build, and a step costs ~1 µs per element (docs/performance.md): 500 000 elements are
# ~10 s to build and ~0.5 s a step, minutes before the first output. The largest shipped
# case or study variant has 237 000 (a 40-layer casing)
LARGE_MESH = 500_000


class CaseInfo(BaseModel):
    """``[case]``: a name and a free description for reports."""

    model_config = STRICT
    name: str = Field(min_length=1)
    description: str = ""


class SectionSpec(BaseModel):
    """``[sections.NAME]``: a shell section (thickness and the stiffnesses the material lacks)."""

    model_config = STRICT
    material: str = Field(min_length=1)
    thickness: Length | None = None
    bending_modulus: quantity("pressure", gt=0, example="1 GPa") | None = None
    bending_poisson: quantity("dimensionless", ge=0, lt=0.5, example="0") | None = None
    transverse_shear_modulus: quantity("pressure", gt=0, example="3.28 GPa") | None = None
    shear_factor: quantity("dimensionless", gt=0, le=1, example="0.8333") = 5.0 / 6.0
    hourglass: quantity("dimensionless", ge=0, lt=1, example="0.05") = 0.05
    areal_mass: quantity("areal_density", gt=0, example="0.477 kg/m^2") | None = None
    # 1: resultant section; odd ≥ 3: Simpson points (default 5 for plastic metals, else 1)
    points: integer(ge=1, example=5) | None = None
    # in-plane membrane integration: "full" 2×2 Gauss points (default for fabric) or
    # "reduced" one point + hourglass springs (default for metals); theory §4.5
    membrane: Literal["full", "reduced"] | None = None


class SolidSectionSpec(BaseModel):
    """``[solid_sections.NAME]``: a solid section, 8-node hexahedra of a transversely
    isotropic material (docs/solid.md) whose fibre axis a1 is ``fibre_direction`` and
    second axis a2 ``second_direction`` projected off a1."""

    model_config = STRICT
    material: str = Field(min_length=1)
    # r of the hourglass stiffness k = r G_hg V0 Σ b⁰·b⁰ (docs/solid.md §1.3)
    hourglass: quantity("dimensionless", ge=0, lt=1, example="0.05") = 0.05
    fibre_direction: Direction = (1.0, 0.0, 0.0)
    # not given: the global axis least aligned with the fibre
    second_direction: Direction | None = None


class BlockMeshSpec(BaseModel):
    """``[mesh] kind = "block"``: a box of 8-node hexahedra of one solid section, ``size``
    along x, y and z from the corner ``origin``, ``elements`` along each edge. Node sets
    ``all``, ``x_min``, ``x_max``, ``y_min``, ``y_max``, ``z_min``, ``z_max`` (its faces)."""

    model_config = STRICT
    kind: Literal["block"]
    size: tuple[Length, Length, Length]
    elements: tuple[integer(ge=1, example=10), integer(ge=1, example=2),
                    integer(ge=1, example=2)]
    origin: tuple[Coordinate, Coordinate, Coordinate] = (0.0, 0.0, 0.0)
    # a solid section (solid_sections)
    section: str = Field(min_length=1)


class CrossoverMeshSpec(BaseModel):
    """``[mesh] kind = "crossover"``: the plain-weave crossover cell of a geometry file
    (``wovenimpact crossover-cell``, docs/solid.md §5), two yarns of hexahedra whose
    material axes follow their centrelines (the solid sections' ``fibre_direction`` and
    ``second_direction`` are not used). Node sets ``warp``, ``fill``, ``warp.x_min``,
    ``warp.x_max``, ``fill.y_min``, ``fill.y_max``, ``warp.top``, ``warp.bottom``,
    ``fill.top``, ``fill.bottom``, ``all``."""

    model_config = STRICT
    kind: Literal["crossover"]
    # the geometry file, relative to the case file
    file: str = Field(min_length=1)
    # a solid section for the warp's hexahedra
    warp_section: str = Field(min_length=1)
    # not given: the warp's
    fill_section: str | None = None


class PlateMeshSpec(BaseModel):
    """``[mesh] kind = "plate"``: square plies from the structured generator, or
    rectangular ones (``side`` along x, ``width`` along y: a strip)."""

    model_config = STRICT
    kind: Literal["plate"]
    side: Length
    # the plate's extent along y; not given: side (a square, the mesh as before the key)
    width: Length | None = None
    element_size: Length
    plies: integer(ge=1, example=4) = 1
    spacing: Length | None = None
    quarter: boolean() = False
    section: str = Field(min_length=1)
    # a section per ply from the lowest (z = 0) up, e.g. fabric plies behind a metal
    # plate; without spacing the plies then touch: mid-planes (t_k + t_k+1)/2 apart
    ply_sections: list[str] | None = None
    warp_direction: Direction = (1.0, 0.0, 0.0)


class ContainmentSetsSpec(BaseModel):
    """``[mesh.containment]`` of an imported mesh: the file's sets that make it a
    containment model (a casing and a fan blade of the user's own geometry, turning about
    the z axis through the origin; theory §8.1). ``blade``: element set of the whole
    blade (relaxed to its spin state); ``root``: node set turned rigidly about the axis;
    ``release``: element set eroded at ``spin.release_time``, which must separate the
    fragment from the hub part; ``fragment``: node set of the released fragment;
    ``casing_layers``: one node or element set per casing layer, innermost first."""

    model_config = STRICT
    blade: str = Field(min_length=1)
    root: str = Field(min_length=1)
    release: str = Field(min_length=1)
    fragment: str = Field(min_length=1)
    casing_layers: list[str] = Field(min_length=1)


class ImportedMeshSpec(BaseModel):
    """``[mesh] kind = "abaqus"`` (an ``.inp`` file) or ``"gmsh"`` (a ``.msh`` file):
    nodes, shell elements (and an ``.inp`` file's 8-node bricks, C3D8R / C3D8: hexahedra
    for solid sections) and sets read through meshio; or ``"lsdyna"`` (a keyword deck,
    ``.k``): nodes, shells, parts (element sets ``PART_<PID>``), sets (``SET_SHELL_<SID>``,
    ``SET_NODE_<SID>``) and the shells' thickness, which a section without ``thickness``
    takes (model/lsdyna.py). ``length_unit`` is the length of one coordinate unit of the
    file ("1 mm" for a mesh drawn in millimetres; default 1 m). ``warp_direction`` is a
    vector projected on each element, or ``"circumferential"``: the hoop direction about
    ``axis`` (through the origin), the warp of a fabric wrapped on a cylinder (a casing).
    Not given, it is
    ``"circumferential"`` for a containment model and x = (1, 0, 0) otherwise.
    ``[mesh.containment]`` names the sets of a containment model
    (:class:`ContainmentSetsSpec`), whose blade spins about the z axis: its ``axis`` is
    z (``check_references``)."""

    model_config = STRICT
    kind: Literal["abaqus", "gmsh", "lsdyna"]
    file: str = Field(min_length=1)
    sections: dict[str, str] = Field(min_length=1)  # element set → section name
    length_unit: quantity("length", gt=0, example="1 mm") = 1.0
    warp_direction: Direction | Literal["circumferential"] | None = None
    axis: Direction = (0.0, 0.0, 1.0)
    containment: ContainmentSetsSpec | None = None

    @field_validator("warp_direction", mode="before")
    @classmethod
    def _vector_or_circumferential(cls, value):
        """One message for a value that is neither (not one per member of the union)."""
        if value is None or value == "circumferential":
            return value
        if isinstance(value, (list, tuple)):
            return check_numbers(value, 3, DIRECTION_VALID)
        raise type_error(f"is {toml_type(value)}, not 'circumferential' or three numbers",
                         "'circumferential' (the hoop direction about mesh.axis), or "
                         + DIRECTION_VALID)

    @property
    def warp(self):
        """``warp_direction``, or its default (see the class docstring)."""
        if self.warp_direction is not None:
            return self.warp_direction
        return "circumferential" if self.containment is not None else (1.0, 0.0, 0.0)


AbaqusMeshSpec = ImportedMeshSpec  # the name of the table before gmsh files were read


Angle = quantity("angle", example="90 deg")


class CasingSpec(BaseModel):
    """``[mesh.casing]``: coaxial cylindrical layers about the z axis (docs/model.md §6).

    The inner metal shell (``inner_section``; omit it for an all-metal casing of
    layers) has its inner surface at ``inner_radius``; ``layers`` layers of
    ``layer_section`` follow outwards, their mid-surfaces ``layer_spacing`` apart
    (default: the layer section's thickness, touching), the first one
    ``layer_spacing``/2 outside the inner shell's outer surface.
    """

    model_config = STRICT
    inner_radius: Length = 0.25
    length: Length = 0.15
    sector: Angle = 2.0 * 3.141592653589793
    centre_angle: quantity("angle", example="90 deg") = 0.0
    # a graded ring: mesh.element_size within fine_sector about centre_angle, growing by
    # at most ~20 % per element to coarse_element_size around the rest (model.casing)
    fine_sector: quantity("angle", gt=0, example="180 deg") | None = None
    coarse_element_size: quantity("length", gt=0, example="14 mm") | None = None
    inner_section: str | None = None
    layer_section: str = Field(min_length=1)
    layers: integer(ge=1, le=200, example=4)
    layer_spacing: Length | None = None
    # every second layer turned by half an element about the axis (full ring only): a
    # node faces an element edge of the next layer, not a corner of four (theory §8)
    offset_layers: boolean() = False
    # the element edge along the axis (z); not given: mesh.element_size. The axial size is
    # the one a casing's answer depends on (theory §8.8): a cylinder's bending boundary
    # layer under a radial load is 0.78 √(R t) long along its axis, long around it
    axial_element_size: quantity("length", gt=0, example="2 mm") | None = None

    @model_validator(mode="after")
    def _grading_needs_both(self):
        if (self.fine_sector is None) != (self.coarse_element_size is None):
            raise ValueError("a graded casing needs both fine_sector and coarse_element_size "
                             "(with units), or neither")
        return self


DEFAULT_STAGGER = math.radians(30.0)  # the default blade's root chord, from the axis
DEFAULT_TWIST = math.radians(30.0)  # and its tip's 30° more: 60° from the axis


class BladeSpec(BaseModel):
    """``[mesh.blade]``: a tapered, twisted blade about the z axis (model.casing).

    Defaults (docs/model.md §7: the thesis's blade is not in its text; theory §8.1): root 40
    mm, split at 60 mm, tip 245 mm (5 mm inside a 250 mm casing), chords 80 mm at the
    root and 40 mm at the tip, radial along ``angle`` (from +x); a fan blade's twist —
    the chord turned 30° from the axial direction at the root and 60° at the tip — and
    a curved tip edge whose corners lie 5 mm inboard. Of 4.98 mm of titanium, the
    released fragment (the airfoil outboard of the crack) weighs 0.229 kg, its centre of
    mass at r = 143.5 mm moving at 150.2 m/s at 1047 rad/s (5 mm elements).

    ``element_size``: the blade's own target element edge (hub part, release row and
    fragment); not given, the casing's ``mesh.element_size`` (theory §8, "The blade's
    own element size").

    ``stagger``: the chord turned from the axial direction towards the tangential one
    at the root; ``twist``: how much more it is turned at the tip (linear along the
    span); ``tip_curve``: the depth of a curved tip edge (a circular arc whose corners
    lie this far inboard of its mid-chord point; the thesis's blade has one). A flat
    blade flying face-on (``stagger``, ``twist`` and ``tip_curve`` 0) loads more of the
    casing and makes it look stronger (theory §8.6).
    """

    model_config = STRICT
    section: str = Field(min_length=1)
    root_radius: Length = 0.04
    crack_radius: Length = 0.06
    tip_radius: Length = 0.245
    root_chord: Length = 0.08
    tip_chord: Length = 0.04
    angle: quantity("angle", example="90 deg") = 0.0
    stagger: quantity("angle", example="30 deg") = DEFAULT_STAGGER
    twist: quantity("angle", example="25 deg") = DEFAULT_TWIST
    tip_curve: quantity("length", ge=0, example="10 mm") = 0.005
    # the blade's own element size (hub part, release row, fragment); absent: the
    # casing's mesh.element_size, so that a casing mesh study can keep the blade fixed
    element_size: quantity("length", gt=0, example="5 mm") | None = None


class ContainmentMeshSpec(BaseModel):
    """``[mesh] kind = "containment"``: a casing and a fan blade (thesis ch. 8). Node
    sets ``casing.ends``, ``casing.end_low``, ``casing.end_high``, ``casing.cut_edges``,
    ``casing.layer{k}``, ``blade.root``, ``blade.hub``, ``blade.fragment``."""

    model_config = STRICT
    kind: Literal["containment"]
    element_size: Length  # the casing's (and the blade's, unless mesh.blade.element_size)
    casing: CasingSpec
    blade: BladeSpec

    @property
    def casing_axial_size(self) -> float:
        """The casing's element edge along the axis: ``mesh.casing.axial_element_size``,
        or ``element_size``."""
        a = self.casing.axial_element_size
        return self.element_size if a is None else a

    @property
    def blade_element_size(self) -> float:
        """The blade's element size: ``mesh.blade.element_size``, or ``element_size``."""
        return self.element_size if self.blade.element_size is None else self.blade.element_size

    @property
    def blade_size_key(self) -> str:
        """The case key that sets :attr:`blade_element_size` (for messages)."""
        return "mesh.element_size" if self.blade.element_size is None else (
            "mesh.blade.element_size")


class SpinSpec(BaseModel):
    """``[spin]``: the blade turns at ``rate`` about the z axis: its centrifugal
    pre-stress by dynamic relaxation, then ω × r velocities (theory §8.1); its root
    keeps turning; the fragment is released at ``release_time`` (theory §8.2)."""

    model_config = STRICT
    # counter-clockwise about +z (the generated blade's stagger and twist, and the fine
    # zone placed downstream of it, assume this sense): > 0; a clockwise rotor is the
    # mirror image of a counter-clockwise one
    rate: quantity("angular_velocity", gt=0, example="1047 rad/s") = 1047.0
    release_time: quantity("time", ge=0, example="0 us") = 0.0
    relaxation_tolerance: quantity("dimensionless", gt=0, lt=0.1, example="1e-5") = 1e-5


class BoundarySpec(BaseModel):
    """``[[boundary]]``: a constraint on a node set."""

    model_config = STRICT
    nodes: str = Field(min_length=1)
    type: Literal["clamped", "pinned", "symmetry_x", "symmetry_y", "symmetry_z", "velocity"]
    dof: Literal["ux", "uy", "uz", "rx", "ry", "rz"] | None = None
    velocity: Velocity | None = None

    @model_validator(mode="after")
    def _velocity_needs_dof(self):
        if self.type == "velocity" and (self.dof is None or self.velocity is None):
            raise ValueError("a 'velocity' boundary needs dof (ux … rz) and velocity (with unit)")
        if self.type != "velocity" and (self.dof is not None or self.velocity is not None):
            raise ValueError(f"dof and velocity belong to type = 'velocity', not {self.type!r}")
        return self


class AmplitudeSpec(BaseModel):
    """``[amplitude]``: rise time of the smooth step applied to prescribed velocities."""

    model_config = STRICT
    ramp_time: quantity("time", ge=0, example="20 us") = 0.0


class InitialVelocitySpec(BaseModel):
    """``[[initial_velocity]]``: translation and/or rigid rotation of a node set at t = 0."""

    model_config = STRICT
    nodes: str = "all"
    velocity: tuple[Velocity, Velocity, Velocity] | None = None
    angular_velocity: tuple[Spin, Spin, Spin] | None = None
    centre: tuple[Coordinate, Coordinate, Coordinate] = (0.0, 0.0, 0.0)
    radius: Length | None = None

    @model_validator(mode="after")
    def _something(self):
        if self.velocity is None and self.angular_velocity is None:
            raise ValueError("give velocity = [vx, vy, vz] and/or angular_velocity = [wx, wy, wz]")
        return self


class BodyForceSpec(BaseModel):
    """``[body_force]``: a uniform acceleration field (gravity, later centrifugal loads)."""

    model_config = STRICT
    acceleration: tuple[Accel, Accel, Accel]


class RunSpec(BaseModel):
    """``[run]``: how long, how often to write, and solver controls."""

    model_config = STRICT
    end_time: Time
    field_interval: Time | None = None
    history_interval: Time | None = None
    checkpoint_interval: Time | None = None
    alpha: quantity("dimensionless", gt=0, le=1, example="0.9") = 0.9
    erode_dt_fraction: quantity("dimensionless", ge=0, lt=1, example="0.05") = 0.05
    # an element crushed through itself is eroded (true) or stops the run (false)
    erode_inverted: boolean() = False
    # selective mass scaling (docs/theory.md §4): elements whose step falls below this
    # fraction of the first get mass so that it is that fraction again (0: off); under
    # stable_step = "yarn" only the wave bound gets mass, not the kinematic limit (which
    # no mass raises)
    mass_scaling_fraction: quantity("dimensionless", ge=0, lt=1, example="0.3") = 0.0
    # the fabric elements' stable step (docs/theory.md §4, "Stable step"): "isotropic",
    # the element's shortest width with the stiffest yarn family per current width
    # (default), or "yarn": each taut family over the element's reference length along
    # it, slack families left out, with a kinematic limit — 2.4–5.6× fewer steps in the
    # hybrid casings of theory §4, but an energy error up to 0.8 % in small-plate
    # perforation (0.28 % with the material option erode_intact_crush = 0.1; the
    # default's up to 0.2 %); not yet the default
    stable_step: Literal["isotropic", "yarn"] = "isotropic"
    # η of the yarn step's kinematic bound (docs/theory.md §4, "Stable step"): the
    # fraction of its distance a corner pair of an element may close or open in one step;
    # only with stable_step = "yarn" (refused otherwise, when not the default 0.05)
    kinematic_fraction: quantity("dimensionless", gt=0, le=0.5,
                                 example="0.25") = KINEMATIC_FRACTION
    # what becomes of a node that loses its last live element (docs/theory.md §5, "Eroded
    # nodes"): "keep" (the default) flies on as a free node with its mass and momentum,
    # contact-active against impactors and other plies' segments (LS-DYNA's ENMASS = 2);
    # "remove" leaves the model with its kinetic energy (eroded_kinetic)
    eroded_nodes: Literal["remove", "keep"] = "keep"
    # the run stops once the added mass exceeds this fraction of the model's mass
    max_added_mass_fraction: quantity("dimensionless", gt=0, le=1, example="0.02") = 0.02
    threads: integer(ge=1, example=2) | None = None
    # largest energy-balance error fraction of a run that ends with exit 0
    # (results.summary.summarise; docs/theory.md §5): 1 %, the report's verdict line; the
    # shipped examples and study variants stay below 4e-3
    energy_tolerance: quantity("dimensionless", gt=0, le=1, example="0.01") = 0.01
    # the predicted step count end_time / Δt₁ above which a run is refused (setup.sanity)
    max_steps: integer(ge=1, example=DEFAULT_MAX_STEPS) = DEFAULT_MAX_STEPS
    # a mesh of more than LARGE_MESH (500 000) elements is refused unless this is true: it
    # takes minutes to build and run on two cores (docs/inputs.md, "Large meshes")
    allow_large_mesh: boolean() = False
    # a containment run ends once its outcome (contained or escaped) has read the same
    # for this long, an escape also with the fragment's speed settled within 0.5 % over
    # it (runs.decision_watch; docs/theory.md §8.3); omitted: it runs to end_time
    stop_when_decided: quantity("time", gt=0, example="500 us") | None = None

    @model_validator(mode="after")
    def _scaling_above_erosion(self):
        f, e = self.mass_scaling_fraction, self.erode_dt_fraction
        if f != 0.0 and f <= e:
            raise ValueError(
                f"mass_scaling_fraction = {f:g} must be 0 (off) or above erode_dt_fraction "
                f"= {e:g}: an element erodes before its step would reach the scaling target"
            )
        if self.kinematic_fraction != KINEMATIC_FRACTION and self.stable_step != "yarn":
            raise ValueError(
                f"kinematic_fraction = {self.kinematic_fraction:g} applies to the kinematic "
                f"bound of stable_step = \"yarn\" only, and stable_step is "
                f"{self.stable_step!r}: set stable_step = \"yarn\" or leave "
                "kinematic_fraction out"
            )
        return self


class ImpactorSpec(BaseModel):
    """``[impactor]``: a rigid body of revolution launched at the structure (docs/model.md §4).

    ``position`` is the nose tip at t = 0, ``direction`` the direction of travel (the
    nose leads), ``velocity`` the speed along it. Mass from ``density`` (steel by
    default) unless ``mass`` is given (the density is then scaled to match).

    ``axis`` (optional) turns the body's axis of revolution across its travel: it must
    be perpendicular to ``direction``, and the body flies sideways — a cylinder lying
    across a strip strikes it with its side, a round edge of its diameter. ``position``
    is then still the tip, the point of the axis where the profile starts (a
    cylinder's first end face's centre), and the body extends ``length`` from it along
    ``axis``. Not given: the axis is the direction of travel, nose first (the model as
    before the key, bit for bit).
    """

    model_config = STRICT
    shape: Literal["sphere", "cylinder"]
    radius: Length
    length: Length | None = None
    nose: Literal["flat", "hemispherical", "conical", "ogive"] = "flat"
    nose_length: quantity("length", ge=0, example="3 mm") = 0.0
    fillet: quantity("length", ge=0, example="0.2 mm") = 0.0
    density: quantity("density", gt=0, example="7922 kg/m^3") = 7922.0
    mass: quantity("mass", gt=0, example="1.1 g") | None = None
    position: tuple[Coordinate, Coordinate, Coordinate]
    direction: Direction = (0.0, 0.0, -1.0)
    axis: Direction | None = None
    velocity: quantity("velocity", gt=0, example="120 m/s")
    contact_stiffness: quantity("dimensionless", gt=0, le=0.5,
                                 example="0.3") = BODY_PENALTY_SCALE
    # dashpot of each node–body pair, a fraction of critical 2 √(k m): 1 makes a struck
    # node come to rest on the face (plastic impact) instead of leaving at twice its speed
    contact_damping: quantity("dimensionless", ge=0, le=2, example="1") = 1.0
    friction: quantity("dimensionless", ge=0, le=10, example="0.2") = 0.0

    @model_validator(mode="after")
    def _cylinder_needs_length(self):
        if self.shape == "cylinder" and self.length is None:
            raise ValueError("a cylinder needs length (with unit)")
        return self


class RigidPlaneSpec(BaseModel):
    """``[[rigid_plane]]``: a rigid plate, a plane of infinite extent through ``point``
    with the unit ``normal`` toward the nodes it meets, moving at the prescribed
    ``velocity`` (scaled by ``[amplitude]`` like a prescribed nodal velocity; not given:
    it holds), meeting the nodes of ``nodes`` by node-to-plane penalty (docs/solid.md §6).
    """

    model_config = STRICT
    point: tuple[Coordinate, Coordinate, Coordinate]
    normal: Direction
    velocity: tuple[Velocity, Velocity, Velocity] = (0.0, 0.0, 0.0)
    nodes: str = "all"
    # its name in the energy books (default "plane" and its index)
    name: str | None = None
    contact_stiffness: quantity("dimensionless", gt=0, le=0.5,
                                 example="0.3") = BODY_PENALTY_SCALE
    # the dashpot of each node–plane pair, a fraction of critical: 1 makes a node come
    # to rest on the plate
    contact_damping: quantity("dimensionless", ge=0, le=2, example="1") = 1.0
    friction: quantity("dimensionless", ge=0, le=10, example="0.2") = 0.0


class ContactSpec(BaseModel):
    """``[contact]``: shell–shell contact (plies on plies, layers on layers; theory §6.3).

    ``surfaces`` says which shells meet: ``"plies"`` (the plies of a plate mesh; for an
    imported mesh the same as ``"parts"``), ``"parts"`` (connected parts of an imported
    mesh), ``"element_sets"`` (the element sets of ``mesh.sections``) or ``"none"``;
    ``self_contact`` also lets a surface meet its own non-adjacent segments.
    """

    model_config = STRICT
    surfaces: Literal["plies", "parts", "element_sets", "none"] = "plies"
    self_contact: boolean() = False
    penalty_scale: quantity("dimensionless", gt=0, le=0.5, example="0.1") = 0.1
    damping: quantity("dimensionless", ge=0, le=2, example="0.3") = 0.3
    friction: quantity("dimensionless", ge=0, le=10, example="0.2") = 0.0
    # the pair dashpot's law (docs/theory.md §6): "always" acts on the relative normal
    # velocity while the pair overlaps, closing or separating; "approach" only while it
    # closes, so a rebound is not damped and surfaces part freely
    damping_mode: Literal["always", "approach"] = "always"


class InitialErosionSpec(BaseModel):
    """``[[initial_erosion]]``: elements eroded at t = 0 (a pre-perforated ply): those
    whose centroid lies within ``radius`` of ``centre`` (in the given plies, default all)."""

    model_config = STRICT
    centre: tuple[Coordinate, Coordinate, Coordinate] = (0.0, 0.0, 0.0)
    radius: Length
    plies: list[integer(ge=0, example=0)] | None = None
    cylinder_axis: Direction | None = (0.0, 0.0, 1.0)


class MaterialRef(BaseModel):
    """``[materials.NAME]`` as a table: a material file and values that replace some of
    its entries (same layout as the file's ``[material]`` table, units included), e.g.
    ``set = { warp = { crimp = "0.06" }, compaction = { a = "0.15 mm" } }``."""

    model_config = STRICT
    file: str = Field(min_length=1)
    set: dict[str, Any] = {}


class CaseSpec(BaseModel):
    """A whole case file."""

    model_config = STRICT
    case: CaseInfo
    materials: dict[str, str | MaterialRef] = Field(min_length=1)
    sections: dict[str, SectionSpec] = {}
    solid_sections: dict[str, SolidSectionSpec] = {}
    mesh: (PlateMeshSpec | ImportedMeshSpec | ContainmentMeshSpec | BlockMeshSpec
           | CrossoverMeshSpec) = Field(discriminator="kind")
    boundary: list[BoundarySpec] = []
    amplitude: AmplitudeSpec = AmplitudeSpec()
    initial_velocity: list[InitialVelocitySpec] = []
    body_force: BodyForceSpec | None = None
    impactor: ImpactorSpec | None = None
    spin: SpinSpec | None = None
    contact: ContactSpec = ContactSpec()
    rigid_plane: list[RigidPlaneSpec] = []
    initial_erosion: list[InitialErosionSpec] = []
    run: RunSpec


def mesh_sections(mesh) -> list[tuple[str, str]]:
    """(key, section name) of every section the mesh table names."""
    if isinstance(mesh, PlateMeshSpec):
        return [("mesh.section", mesh.section)] + [
            (f"mesh.ply_sections[{k}]", s) for k, s in enumerate(mesh.ply_sections or ())]
    if isinstance(mesh, ImportedMeshSpec):
        return [("mesh.sections", s) for s in mesh.sections.values()]
    if isinstance(mesh, BlockMeshSpec):
        return [("mesh.section", mesh.section)]
    if isinstance(mesh, CrossoverMeshSpec):
        return [("mesh.warp_section", mesh.warp_section)] + (
            [] if mesh.fill_section is None else [("mesh.fill_section", mesh.fill_section)])
    out = [("mesh.casing.layer_section", mesh.casing.layer_section),
           ("mesh.blade.section", mesh.blade.section)]
    if mesh.casing.inner_section is not None:
        out.append(("mesh.casing.inner_section", mesh.casing.inner_section))
    return out


def is_containment_spec(spec: CaseSpec) -> bool:
    """A generated containment mesh, or an imported one naming its containment sets."""
    m = spec.mesh
    return isinstance(m, ContainmentMeshSpec) or (
        isinstance(m, ImportedMeshSpec) and m.containment is not None)


def check_references(spec: CaseSpec) -> list[Problem]:
    """Cross-references a schema cannot see: section → material, mesh → section."""
    problems = []
    if not spec.sections and not spec.solid_sections:
        problems.append(Problem("sections", "is missing", valid="a [sections.NAME] table "
                                "(shells) or a [solid_sections.NAME] table (hexahedra)"))
    for table in ("sections", "solid_sections"):
        for name, sec in getattr(spec, table).items():
            if sec.material not in spec.materials:
                problems.append(Problem(f"{table}.{name}.material", "names no material",
                                        sec.material, f"one of {sorted(spec.materials)}"))
    for name in sorted(set(spec.sections) & set(spec.solid_sections)):
        problems.append(Problem(f"solid_sections.{name}", "has the name of a shell section",
                                valid="a name not used in [sections]"))
    known = sorted(set(spec.sections) | set(spec.solid_sections))
    for key, s in mesh_sections(spec.mesh):
        if s not in known:
            problems.append(Problem(key, "names no section", s, f"one of {known}"))
    if isinstance(spec.mesh, (BlockMeshSpec, CrossoverMeshSpec)):
        for key, s in mesh_sections(spec.mesh):
            if s in spec.sections:
                problems.append(Problem(key, "names a shell section", s, "a solid section, "
                                        f"one of {sorted(spec.solid_sections)}"))
    if not isinstance(spec.mesh, (BlockMeshSpec, CrossoverMeshSpec, ImportedMeshSpec)):
        for key, s in mesh_sections(spec.mesh):
            if s in spec.solid_sections:
                problems.append(Problem(key, "names a solid section", s, "a shell section, "
                                        f"one of {sorted(spec.sections)}"))
    if is_containment_spec(spec) and spec.spin is None:
        problems.append(Problem("spin", "is missing", valid="a [spin] table (rate, "
                                "release_time) for a containment case"))
    if spec.spin is not None and not is_containment_spec(spec):
        problems.append(Problem("spin", "needs a blade to turn", valid="mesh.kind = "
                                "'containment', or an imported mesh with a "
                                "[mesh.containment] table naming its blade's sets"))
    if isinstance(spec.mesh, ImportedMeshSpec) and spec.mesh.containment is not None and (
            tuple(spec.mesh.axis) != (0.0, 0.0, 1.0)):
        problems.append(Problem("mesh.axis", "must be the z axis for a containment model",
                                list(spec.mesh.axis), "[0, 0, 1]: the blade turns and the "
                                "casing's radii are measured about the z axis through the "
                                "origin; place the model so"))
    im = spec.impactor
    if im is not None and im.axis is not None:
        a, d = im.axis, im.direction
        cos = sum(x * y for x, y in zip(a, d)) / (math.hypot(*a) * math.hypot(*d))
        if abs(cos) > SIDEWAYS_COS:
            angle = math.degrees(math.acos(max(-1.0, min(1.0, cos))))
            problems.append(Problem(
                "impactor.axis", f"is not perpendicular to impactor.direction = "
                f"{list(d)} (the angle between them is {angle:.6g}°)", list(a),
                "a vector perpendicular to the direction, for a body flying sideways such "
                "as a cylinder whose side strikes as an edge; or no axis: the body's axis "
                "along its direction, nose first"))
    plate = isinstance(spec.mesh, PlateMeshSpec)
    if plate and spec.mesh.ply_sections is not None and (
            len(spec.mesh.ply_sections) != spec.mesh.plies):
        problems.append(Problem("mesh.ply_sections", f"has {len(spec.mesh.ply_sections)} "
                                "entries", spec.mesh.ply_sections,
                                f"one section per ply ({spec.mesh.plies}), lowest first"))
    if (plate and spec.mesh.plies > 1 and spec.mesh.spacing is None
            and spec.mesh.ply_sections is None):
        problems.append(Problem("mesh.spacing", "is missing", valid="the distance between ply "
                                "mid-planes, e.g. '0.5 mm', needed when plies > 1 "
                                "(or ply_sections: touching plies)"))
    return problems + check_mesh_size(spec.mesh, spec.run.allow_large_mesh)


def check_mesh_size(m, allow_large: bool = False) -> list[Problem]:
    """A generated mesh must have at least 2 elements along each modelled edge (a quarter
    plate's edge is half the side; a casing's length and the released fragment) and at
    most MAX_ELEMENTS elements in all; more than LARGE_MESH only with ``allow_large``
    (``run.allow_large_mesh``)."""
    if isinstance(m, PlateMeshSpec):
        counts = []
        for name, length in (("side", m.side), ("width", m.width)):
            if length is None:  # a square: the width's count is the side's
                counts.append(counts[0])
                continue
            edge = length / 2.0  # the generator puts round(L/2 / h) elements on a half
            ratio = edge / m.element_size  # a float: 1e30 mm / 1e-300 mm must not overflow
            per_half = round(ratio) if ratio < 1e15 else ratio
            if per_half < 2:
                where = ("the quarter plate's edge" if m.quarter
                         else "each half of the plate's side")
                if m.width is not None:  # a rectangle: which of its lengths
                    where = f"half of mesh.{name}"
                return [Problem("mesh.element_size", f"gives {per_half} element(s) along "
                                f"{where} ({edge:g} m)", m.element_size,
                                f"element_size ≤ {edge / 1.5:.4g} m (2 elements or more)")]
            counts.append(float(per_half) * (1 if m.quarter else 2))
        count = counts[0] * counts[1] * m.plies
        context = (f"side {m.side:g} m, {m.plies} plies" if m.width is None
                   else f"side {m.side:g} m, width {m.width:g} m, {m.plies} plies")
    elif isinstance(m, BlockMeshSpec):
        count = float(math.prod(m.elements))
        if count > MAX_ELEMENTS or (count > LARGE_MESH and not allow_large):
            limit = MAX_ELEMENTS if count > MAX_ELEMENTS else LARGE_MESH
            return [Problem("mesh.elements", f"gives {count:.3g} hexahedra, more than "
                            f"{limit:,}", list(m.elements), "fewer elements" + (
                                "" if count > MAX_ELEMENTS else ", or run.allow_large_mesh "
                                "= true to build them all the same"))]
        return []
    elif isinstance(m, ContainmentMeshSpec):
        c, b = m.casing, m.blade
        fragment = b.tip_radius - b.crack_radius
        axial_key = "mesh.element_size"
        if c.axial_element_size is None and b.element_size is None:
            # one size: the shorter of casing length and fragment
            edges = [("mesh.element_size", m.element_size, min(c.length, fragment),
                      "the casing's length or the released fragment")]
        else:
            if c.axial_element_size is not None:
                axial_key = "mesh.casing.axial_element_size"
            edges = [(axial_key, m.casing_axial_size, c.length, "the casing's length"),
                     (m.blade_size_key, m.blade_element_size, fragment,
                      "the released fragment")]
        few = [Problem(key, f"gives fewer than 2 elements along {where} ({edge:g} m)", h,
                       f"element_size ≤ {edge / 2.0:.4g} m")
               for key, h, edge, where in edges if h > edge / 2.0]
        if few:
            return few
        arc = c.sector  # a graded ring: its coarse part as the equivalent fine arc
        if c.fine_sector is not None and c.coarse_element_size is not None:
            fine = min(c.fine_sector, c.sector)
            arc = fine + (c.sector - fine) * min(m.element_size / c.coarse_element_size, 1.0)
        casing = arc * c.inner_radius * c.length * (c.layers + 1)
        blade = (b.tip_radius - b.root_radius) * max(b.root_chord, b.tip_chord)
        hb = m.blade_element_size
        # no underflow to 0 at 1e-300: each area over the size, then over it again
        in_casing, in_blade = casing / m.element_size / m.casing_axial_size, blade / hb / hb
        count = in_casing + in_blade
        context = f"casing and blade, {c.layers} layers"
        if in_blade > in_casing and b.element_size is not None:
            return _too_many(count, "mesh.blade.element_size", hb, context, allow_large)
    else:
        return []
    return _too_many(count, "mesh.element_size", m.element_size, context, allow_large)


def _too_many(count: float, key: str, size: float, context: str,
              allow_large: bool = False) -> list[Problem]:
    """A count of elements above MAX_ELEMENTS, or above LARGE_MESH without
    ``allow_large``, blamed on ``key`` (= ``size``)."""
    if count > MAX_ELEMENTS:
        return [Problem(key, f"gives about {count:.3g} elements ({context})", size,
                        f"at most {MAX_ELEMENTS:g} elements in the mesh")]
    if count > LARGE_MESH and not allow_large:
        # the count goes as 1/size²: the size that gives LARGE_MESH elements
        fit = size * math.sqrt(count / LARGE_MESH) if math.isfinite(count) else math.inf
        return [Problem(key, f"gives about {count:.3g} elements ({context}), more than "
                        f"{LARGE_MESH:,}: a mesh that takes minutes to build and run on two "
                        f"cores (~10 s to build and ~0.5 s a step per {LARGE_MESH:,} "
                        "elements)", size, f"{key} ≥ about {fit * 1e3:.3g} mm, or "
                        "run.allow_large_mesh = true (--set run.allow_large_mesh=true) to "
                        "build it all the same")]
    return []


INTERVALS = ("field_interval", "history_interval", "checkpoint_interval")
QUARTER_SETS = ("symmetry_x", "symmetry_y")


def _time_text(seconds: float) -> str:
    """A time for a message, in µs below a millisecond (case files mostly say "us")."""
    return f"{seconds * 1e6:g} us" if seconds < 1e-3 else f"{seconds:g} s"


def clipped_intervals(spec: CaseSpec, source: str = "<dict>") -> CaseSpec:
    """``spec`` with every output interval longer than ``run.end_time`` set to the end time
    (a shortened run, e.g. ``--set run.end_time="5 us"``, just writes its outputs at the
    end), each change told by an :class:`~wovenimpact.errors.InputWarning` naming the key."""
    run = spec.run
    changes = {}
    for key in INTERVALS:
        value = getattr(run, key)
        if value is not None and value > run.end_time:
            changes[key] = run.end_time
            warnings.warn(f"{source}: run.{key} = {_time_text(value)} is longer than "
                          f"run.end_time = {_time_text(run.end_time)}: clipped to the end time",
                          InputWarning, stacklevel=3)
    if not changes:
        return spec
    return spec.model_copy(update={"run": run.model_copy(update=changes)})


def missing_symmetry_sets(spec: CaseSpec) -> list[str]:
    """The symmetry node sets of a quarter plate (``mesh.quarter = true``) that no
    ``[[boundary]]`` constrains: without them the quarter is a free-edged small plate."""
    if not (isinstance(spec.mesh, PlateMeshSpec) and spec.mesh.quarter):
        return []
    constrained = {b.nodes for b in spec.boundary}
    return [name for name in QUARTER_SETS if name not in constrained]


def warn_missing_symmetry(spec: CaseSpec, source: str = "<dict>") -> None:
    """An :class:`~wovenimpact.errors.InputWarning` naming the sets of
    :func:`missing_symmetry_sets`, with the boundary tables that would constrain them."""
    missing = missing_symmetry_sets(spec)
    if missing:
        tables = " ".join(f'[[boundary]] nodes = "{m}", type = "{m}";' for m in missing)
        warnings.warn(f"{source}: mesh.quarter = true but no boundary constrains "
                      f"{' and '.join(missing)} (add {tables.rstrip(';')})",
                      InputWarning, stacklevel=3)


def _without_mesh_kind(p: Problem) -> Problem:
    """``mesh.plate.side`` → ``mesh.side``: the kind selects the table, it is not a key."""
    for kind in ("plate", "abaqus", "gmsh", "lsdyna", "containment", "block", "crossover"):
        if p.path.startswith(f"mesh.{kind}."):
            return dataclasses.replace(p, path="mesh." + p.path[len(kind) + 6:])
    return p


def case_from_dict(doc: dict[str, Any], source: str = "<dict>") -> CaseSpec:
    """Validate a parsed case document; all problems are raised in one InputError."""
    try:
        spec = CaseSpec.model_validate(doc)
    except ValidationError as err:
        problems = [_without_mesh_kind(p) for p in problems_from_validation(err, CaseSpec)]
        raise input_error(problems, source) from None
    problems = check_references(spec)
    if problems:
        raise input_error(problems, source)
    warn_missing_symmetry(spec, source)
    return clipped_intervals(spec, source)


def load_case(path: str | Path, overrides=()) -> tuple[CaseSpec, Path]:
    """Read and validate a case file, with the command line's ``KEY=VALUE`` overrides
    (``--set``) applied first; returns the spec and the file's directory (material and
    mesh paths in the case are relative to it)."""
    path = Path(path)
    doc = apply_overrides(read_toml(path, "case file"), overrides)
    source = str(path) + "".join(f" --set {o!r}" for o in overrides or ())
    return case_from_dict(doc, source=source), path.resolve().parent
