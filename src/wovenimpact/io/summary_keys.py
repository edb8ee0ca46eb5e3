"""What each summary.json key means, in which unit a person reads it, and where it goes.

One table, :data:`KEYS`: key → :class:`Key` (group, label, unit, scale, meaning). The run's
report.html (:mod:`wovenimpact.io.report`) and the console summary of ``wovenimpact run``
(:mod:`wovenimpact.cli.app`) both show the summary grouped by it:

- ``answer``: what happened (outcome, exit or residual speed, absorbed energy, bulge or
  deflection);
- ``energies``: the energy books at the end, whole problem (J);
- ``structure``: the casing and the fragment, or the plies, part by part;
- ``run``: the run itself and the numbers that say how far to trust it (element size,
  mesh verdict, energy error, hourglass share, added mass, time steps, wall time);
- ``other``: any key this table does not know (a newer summary, a study's own), shown as
  it is — nothing is dropped.

summary.json itself stays in SI units and snake_case keys (scripts and studies read
it); only what is shown is scaled (``value × scale`` in ``unit``: metres as mm, seconds
as ms or µs, fractions as %). :data:`INTERNAL` keys are not shown in the grouped table
(the page's provenance section has them).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Key:
    """How a summary key is shown: in ``group``, as ``label``, its value × ``scale`` in
    ``unit`` ("" for a count, a word or a yes/no), with a one-line ``meaning``."""

    group: str
    label: str
    unit: str = ""
    scale: float = 1.0
    meaning: str = ""


GROUPS = ("answer", "energies", "structure", "run", "other")
GROUP_TITLES = {"answer": "Answer", "energies": "Energies (whole problem, at the end)",
                "structure": "Plies", "run": "Run and checks",
                "other": "Other keys (not described by this version)"}
CONTAINMENT_STRUCTURE_TITLE = "Casing and fragment"
INTERNAL = ("summary_version", "provenance")  # shown in the page's provenance section

_A, _E, _S, _R = "answer", "energies", "structure", "run"
MM, MS, US, PCT = ("mm", 1e3), ("ms", 1e3), ("µs", 1e6), ("%", 100.0)

KEYS: dict[str, Key] = {
    # --- answer: containment
    "outcome": Key(_A, "outcome", meaning="plate: stopped, perforated or no contact; casing: "
                   "contained or escaped; undecided: not yet decided at the end (run longer)"),
    "contained": Key(_A, "contained", meaning="the fragment stayed inside the casing"),
    "fragment_exit_speed_m_per_s": Key(
        _A, "fragment exit speed", "m/s",
        meaning="an escaped fragment's centre-of-mass speed at the end; 0 if contained; "
                "none while undecided"),
    "fragment_speed_at_end_m_per_s": Key(
        _A, "fragment speed at the end", "m/s",
        meaning="its centre-of-mass speed at the last step, whatever the outcome"),
    "fragment_exit_speed_settled": Key(
        _A, "exit speed settled", meaning="an escaped fragment's speed stayed within 0.5 % "
        "over the last 500 µs (none unless escaped); no: run longer"),
    "casing_absorbed_energy_J": Key(
        _A, "energy absorbed by the casing", "J",
        meaning="contact work the casing layers received, summed over the layers"),
    "max_bulge_m": Key(_A, "largest bulge", *MM,
                       meaning="largest outward radial displacement of the outermost layer "
                               "(nodes still held by the supports), over the run"),
    "stopped_when_decided": Key(
        _A, "stopped when decided", meaning="the outcome that ended the run early "
        "(run.stop_when_decided); none: it ran to its end time"),
    "outcome_decided_at_s": Key(
        _A, "outcome decided at", *US,
        meaning="from this time on every history row read the final outcome; none: "
                "undecided (or, for a plate, no contact)"),
    # --- answer: plate impact
    "perforated": Key(_A, "perforated", meaning="the impactor passed every ply"),
    "residual_velocity_m_per_s": Key(
        _A, "residual velocity", "m/s",
        meaning="the impactor's velocity along its travel after perforation; 0 if stopped"),
    "rebound_velocity_m_per_s": Key(_A, "rebound velocity", "m/s",
                                    meaning="the speed a stopped impactor bounced back with"),
    "initial_velocity_m_per_s": Key(_A, "impact velocity", "m/s",
                                    meaning="the impactor's velocity at the start"),
    "absorbed_energy_J": Key(_A, "energy absorbed", "J",
                             meaning="the kinetic energy the impactor lost (start − end)"),
    "max_deflection_m": Key(_A, "largest deflection", *MM,
                            meaning="largest displacement of a ply node at the end"),
    "peak_contact_force_N": Key(_A, "peak contact force", "kN", 1e-3,
                                meaning="largest contact force on the impactor, whole problem"),
    # --- energies
    "initial_total_kinetic_energy_J": Key(_E, "initial kinetic energy", "J",
                                          meaning="nodes and impactors at t = 0"),
    "initial_structure_kinetic_energy_J": Key(
        _E, "initial kinetic energy, structure", "J",
        meaning="the nodes' at t = 0 (a spinning blade's included)"),
    "initial_impactor_kinetic_energy_J": Key(_E, "initial kinetic energy, impactor", "J",
                                             meaning="the rigid impactors' at t = 0"),
    "total_kinetic_energy_J": Key(_E, "kinetic energy", "J", meaning="nodes and impactors"),
    "structure_kinetic_energy_J": Key(_E, "kinetic energy, structure", "J",
                                      meaning="the nodes' (casing and blade, or plies)"),
    "impactor_kinetic_energy_J": Key(_E, "kinetic energy, impactor", "J",
                                     meaning="the rigid impactors'"),
    "internal_work_J": Key(_E, "internal work", "J",
                           meaning="stored + hourglass + eroded internal + dissipated"),
    "stored_energy_J": Key(_E, "stored energy", "J",
                           meaning="elastic energy of the live elements"),
    "hourglass_energy_J": Key(_E, "hourglass energy", "J",
                              meaning="held by the live elements' hourglass control"),
    "eroded_internal_energy_J": Key(_E, "eroded internal energy", "J",
                                    meaning="what eroded elements held when they eroded"),
    "eroded_hourglass_energy_J": Key(_E, "eroded hourglass energy", "J",
                                     meaning="its hourglass part"),
    "eroded_kinetic_energy_J": Key(_E, "eroded kinetic energy", "J",
                                   meaning="carried off by nodes freed by erosion"),
    "plastic_work_J": Key(_E, "plastic work", "J",
                          meaning="plastic work of the metal sections (part of the internal work)"),
    "external_work_J": Key(_E, "external work", "J",
                           meaning="body forces + reactions of supports and prescribed motions"),
    "body_force_work_J": Key(_E, "body-force work", "J", meaning="gravity's"),
    "reaction_work_J": Key(_E, "reaction work", "J",
                           meaning="of the supports and prescribed motions (a blade's spin)"),
    "contact_energy_J": Key(_E, "contact energy", "J",
                            meaning="−(work of the contact forces): penalty springs' energy "
                                    "plus what dashpots and friction dissipated"),
    "contact_damping_energy_J": Key(_E, "contact damping", "J",
                                    meaning="dissipated by the contact dashpots"),
    "contact_friction_energy_J": Key(_E, "contact friction", "J",
                                     meaning="dissipated by friction"),
    "contact_damping_energy_by_interface_J": Key(
        _E, "contact damping per interface", "J",
        meaning="the same, pair by pair (interfaces where contact acted)"),
    "contact_friction_energy_by_interface_J": Key(_E, "contact friction per interface", "J",
                                                  meaning="the same, pair by pair"),
    "mass_scaling_energy_J": Key(_E, "energy of the added mass", "J",
                                 meaning="kinetic energy the mass scaling's added mass brought "
                                         "(an input of the balance)"),
    # --- structure: casing and fragment
    "fragment_mass_kg": Key(_S, "fragment mass", "kg", meaning="the released blade fragment's"),
    "fragment_initial_speed_m_per_s": Key(_S, "fragment initial speed", "m/s",
                                          meaning="its centre-of-mass speed at the start"),
    "casing_layers": Key(_S, "casing layers", meaning="node sets casing.layer0, 1, … counted: "
                         "the inner metal shell, if the casing has one, is the first"),
    "casing_mass_kg": Key(_S, "casing mass", "kg", meaning="all its layers (modelled part)"),
    "casing_mass_per_area_kg_per_m2": Key(_S, "casing areal mass", "kg/m²",
                                          meaning="each layer's mass per area, summed through "
                                                  "the wall"),
    "absorbed_energy_per_layer_J": Key(_S, "absorbed energy per layer", "J",
                                       meaning="contact work each layer received, innermost "
                                               "first (what it kept, not what it passed on)"),
    "held_energy_per_layer_J": Key(_S, "energy held per layer", "J",
                                   meaning="kinetic + stored + hourglass each layer holds at "
                                           "the end, innermost first (not what it absorbed: "
                                           "dissipated and eroded energy is gone from it)"),
    "absorbed_energy_per_material_J": Key(_S, "absorbed energy per material", "J",
                                          meaning="the layers' absorbed energy summed by "
                                                  "material"),
    "layer_perforated_at_s": Key(_S, "layer first perforated at", *US,
                                 meaning="per layer, innermost first: the first time no "
                                         "intact material of it lay outside the fragment "
                                         "along its path; none: not perforated"),
    # --- structure: plies
    "absorbed_energy_per_ply_J": Key(_S, "energy absorbed per ply", "J",
                                     meaning="kinetic + stored energy of each ply at the end "
                                             "(eroded elements' at erosion) + a metal ply's "
                                             "plastic work; broken yarns' work is in the "
                                             "contact work per ply"),
    "contact_work_per_ply_J": Key(_S, "contact work per ply", "J",
                                  meaning="work the contact forces did on each ply's nodes"),
    "ply_perforated_at_s": Key(_S, "ply first perforated at", *US,
                               meaning="per ply: the first time none of its intact material "
                                       "within the impactor's reach lay ahead of the nose; "
                                       "none: not perforated"),
    "max_deflection_per_ply_m": Key(_S, "largest deflection per ply", *MM,
                                    meaning="each ply's largest node displacement at the end"),
    "eroded_elements": Key(_S, "eroded elements", meaning="elements failed and removed"),
    "max_displacement_m": Key(_S, "largest displacement", *MM,
                              meaning="of any node at the end (a blade's spin included)"),
    # --- run and checks
    "case": Key(_R, "case", meaning="[case] name"),
    "finished_utc": Key(_R, "finished (UTC)", meaning="when this summary was written"),
    "element_size_m": Key(_R, "element size", *MM,
                          meaning="mesh.element_size (a casing's fine sector); an imported "
                                  "mesh: median √(element area); hexahedra only: median "
                                  "∛(element volume)"),
    "blade_element_size_m": Key(_R, "blade element size", *MM,
                                meaning="mesh.blade.element_size, else the casing's"),
    "casing_axial_element_size_m": Key(_R, "casing element size along the axis", *MM,
                                       meaning="mesh.casing.axial_element_size (given: the "
                                               "casing's elements are element size around, "
                                               "this along the axis)"),
    "mesh_verdict": Key(_R, "mesh verdict",
                        meaning="each failing material's elements against the sizes its "
                                "failure law is calibrated for (docs/theory.md §1.4)"),
    "energy_error_fraction": Key(_R, "energy error", *PCT,
                                 meaning="largest energy-balance drift over the energy put in"),
    "energy_tolerance": Key(_R, "energy tolerance", *PCT, meaning="run.energy_tolerance"),
    "energy_check": Key(_R, "energy check", meaning="pass: the error is within the tolerance"),
    "hourglass_fraction": Key(_R, "hourglass share", *PCT,
                              meaning="hourglass energy (live and eroded) over internal work"),
    "added_mass_kg": Key(_R, "added mass", "g", 1e3, meaning="mass scaling's (whole problem)"),
    "added_mass_fraction": Key(_R, "added mass share", *PCT, meaning="of the model's mass"),
    "mass_scaled_elements": Key(_R, "mass-scaled elements", meaning="elements given mass"),
    "end_time_s": Key(_R, "end time", *MS, meaning="simulated time reached"),
    "steps": Key(_R, "steps", meaning="time steps taken"),
    "elements": Key(_R, "elements", meaning="shell elements and hexahedra of the model"),
    "nodes": Key(_R, "nodes", meaning="nodes of the model"),
    "first_time_step_s": Key(_R, "first time step", *US, meaning="the stable step at the start"),
    "last_time_step_s": Key(_R, "last time step", *US, meaning="the step at the end"),
    "wall_time_s": Key(_R, "wall time", "s", meaning="of every invocation (restarts included)"),
    "element_cycles": Key(_R, "element cycles", meaning="steps × elements"),
    "ns_per_element_cycle": Key(_R, "cost per element cycle", "ns",
                                 meaning="wall time over element cycles"),
    "symmetry_factor": Key(_R, "symmetry factor",
                           meaning="whole problem / modelled part (4 in a quarter model)"),
    "restarted_from_step": Key(_R, "restarted from step", meaning="none: not restarted"),
}


@dataclass(frozen=True)
class Row:
    """One shown row of a summary: its key, label, value text in ``unit``, meaning."""

    key: str
    label: str
    value: str
    unit: str
    meaning: str


def _plain(v):
    """NumPy scalars and arrays as Python numbers and lists."""
    if hasattr(v, "tolist") and not isinstance(v, (str, bytes)):
        return v.tolist()
    return v


def number(v, scale: float = 1.0) -> str:
    """A value × ``scale`` as text: 4 significant digits, integers whole, lists and
    mappings item by item, None as "none", booleans as yes/no."""
    v = _plain(v)
    if v is None:
        return "none"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int) and scale == 1.0:
        return str(v)
    if isinstance(v, (int, float)):
        x = float(v) * scale + 0.0  # + 0.0: −0 reads 0
        return "—" if not math.isfinite(x) else f"{x:.4g}"
    if isinstance(v, Mapping):
        return "; ".join(f"{k}: {number(x, scale)}" for k, x in v.items()) or "none"
    if isinstance(v, (list, tuple)):
        return ", ".join(number(x, scale) for x in v) or "none"
    return str(v)


def row(key: str, value) -> Row:
    """The row of ``key`` (an unknown key: as it is, under its own name)."""
    k = KEYS.get(key)
    if k is None:
        return Row(key, key, number(value), "", "")
    if key == "mesh_verdict":
        from wovenimpact.results.mesh_verdict import verdict_text

        text = verdict_text(value)[0] if isinstance(value, Mapping) else number(value)
        return Row(key, k.label, text, "", k.meaning)
    return Row(key, k.label, number(value, k.scale), k.unit, k.meaning)


def is_containment_summary(summary: Mapping) -> bool:
    """Whether a summary is of a containment run (a blade fragment and a casing)."""
    return "fragment_exit_speed_m_per_s" in summary or "casing_layers" in summary


def grouped(summary: Mapping) -> list[tuple[str, str, list[Row]]]:
    """The summary's rows by group, in :data:`GROUPS` order and, within a group, in the
    table's order (unknown keys in "other", in the summary's order): (group, title,
    rows) for every group that has one. :data:`INTERNAL` keys are left out."""
    titles = dict(GROUP_TITLES)
    if is_containment_summary(summary):
        titles["structure"] = CONTAINMENT_STRUCTURE_TITLE
    rows: dict[str, list[Row]] = {g: [] for g in GROUPS}
    for key, k in KEYS.items():
        if key in summary:
            rows[k.group].append(row(key, summary[key]))
    for key, value in summary.items():
        if key not in KEYS and key not in INTERNAL:
            rows["other"].append(row(key, value))
    return [(g, titles[g], rows[g]) for g in GROUPS if rows[g]]
