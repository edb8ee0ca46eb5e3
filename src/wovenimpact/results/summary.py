"""summary.json: the numbers a user wants from a finished run (:func:`summarise`), the
keys a case's summary has (:func:`summary_keys`, the metrics a study may ask for) and the
version of its rules (:data:`SUMMARY_VERSION`: an older summary is not reused).

Energies here are of the whole problem (the modelled part's × ``symmetry_factor``). The
run loop (:mod:`wovenimpact.runs`) adds ``restarted_from_step``, ``stopped_when_decided``
and ``provenance`` and writes the file; :mod:`wovenimpact.io.summary_keys` says how each
key is shown.
"""

from __future__ import annotations

import time

import numpy as np

from wovenimpact.interfaces import booked_totals, interface_energies
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.contact_energy import DAMPING, FRICTION
from wovenimpact.results.containment import casing_summary, is_containment, layer_elements
from wovenimpact.results.energy import energy_balance, error_fraction
from wovenimpact.results.history_rows import mass_scaling_row
from wovenimpact.results.mesh_verdict import SUMMARY_KEY as MESH_VERDICT_KEY
from wovenimpact.results.mesh_verdict import mesh_verdict
from wovenimpact.results.metal_state import has_metal, plastic_work
from wovenimpact.results.quantities import (
    outcome_decided_at,
    ply_contact_work,
    ply_deflections,
    ply_energies,
    ply_perforation_times,
    residual_velocity,
    symmetry_factor,
)
from wovenimpact.state import KINETIC0, State

SUMMARY_VERSION = 4  # 2: issue 9's outcome rule and energy keys; 3: issue 12's energy
#                     normalisation and provenance; 4: a casing layer's absorbed energy is
#                     the contact work it received (held_energy_per_layer_J the old
#                     figure); older summaries are re-run


def summarise(spec, model, state: State, wall: float, h: dict) -> dict:
    """The numbers a user wants from a finished run (summary.json). Energies here are
    of the whole problem (the modelled part's × ``symmetry_factor``):

    - ``structure_kinetic_energy_J`` (nodes), ``impactor_kinetic_energy_J`` (rigid
      bodies) and ``total_kinetic_energy_J`` (both) at the end;
      ``initial_total_kinetic_energy_J`` (both, t = 0) with its parts
      ``initial_structure_kinetic_energy_J`` and ``initial_impactor_kinetic_energy_J``;
    - ``internal_work_J`` = stored (live elements) + hourglass (live elements) + eroded
      internal (energies of eroded elements at erosion) + dissipated, each joule once;
    - ``hourglass_fraction`` = (``hourglass_energy_J`` of live elements +
      ``eroded_hourglass_energy_J``, what eroded ones held at erosion) / internal work
      (docs/theory.md §5), None while the internal work is not positive;
    - ``energy_error_fraction``: the largest |drift| of the history over the largest
      energy put into the model (its last ``energy_normaliser_part_J``), and ``energy_check``
      "pass" if it is at most ``energy_tolerance`` (``run.energy_tolerance``), else "fail"
      (the CLI then exits with code 4);
    - ``contact_damping_energy_J`` and ``contact_friction_energy_J``: what the contact
      dashpots and friction dissipated, and the same per interface
      (``*_by_interface_J``, :func:`contact_damping_summary`);
    - ``element_cycles``, ``wall_time_s`` and ``ns_per_element_cycle`` of every
      invocation that made this result (a restarted run's included).

    ``spec`` is the run's case (:class:`~wovenimpact.spec.case.CaseSpec`: its name, mesh
    and ``run.energy_tolerance``), ``model`` the Model compiled from it and ``h`` the
    history's columns (:meth:`wovenimpact.io.history.History.arrays`).
    """
    eb = energy_balance(model, state)
    cycles = state.step * (model.n_elems + model.n_hexes)
    error = error_fraction(np.max(np.abs(h["energy_drift_part_J"])),
                           h["energy_normaliser_part_J"][-1])
    factor = symmetry_factor(model)
    impact = {}
    if is_containment(model):
        impact = casing_summary(model, state, h)
    ke_body0 = 0.0
    if model.body_params.shape[0]:
        ke_body0 = factor * float(h["impactor_kinetic_energy_part_J"][0])
        ke1 = factor * eb["impactor_kinetic_J"]
        per_ply = ply_energies(model, state)
        impact = {
            **residual_velocity(h),
            "ply_perforated_at_s": ply_perforation_times(h),
            "outcome_decided_at_s": outcome_decided_at(h),
            "initial_velocity_m_per_s": float(h["impactor_velocity_m_per_s"][0]),
            "absorbed_energy_J": ke_body0 - ke1,
            "absorbed_energy_per_ply_J": per_ply,
            "contact_work_per_ply_J": ply_contact_work(model, state),
            "max_deflection_m": max(ply_deflections(model, state)),
            "max_deflection_per_ply_m": ply_deflections(model, state),
            "peak_contact_force_N": float(np.max(h["contact_force_full_N"])),
        }
    w_int = eb["internal_work_J"]
    hg_all = eb["hourglass_J"] + eb["eroded_hourglass_J"]
    return {**impact,
        "summary_version": SUMMARY_VERSION,
        # when this summary was written (UTC): a report that reuses the run can say so
        "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "case": spec.case.name,
        "end_time_s": float(state.t),
        "steps": int(state.step),
        "elements": int(model.n_elems + model.n_hexes),
        "nodes": int(model.n_nodes),
        "first_time_step_s": float(state.dt_first),
        "last_time_step_s": float(state.dt),
        "wall_time_s": wall,
        "element_cycles": int(cycles),
        "ns_per_element_cycle": wall / cycles * 1e9 if cycles else None,
        "structure_kinetic_energy_J": factor * eb["kinetic_J"],
        "impactor_kinetic_energy_J": factor * eb["impactor_kinetic_J"],
        "total_kinetic_energy_J": factor * (eb["kinetic_J"] + eb["impactor_kinetic_J"]),
        "initial_total_kinetic_energy_J": factor * float(state.energy[KINETIC0]),
        "initial_structure_kinetic_energy_J": factor * float(state.energy[KINETIC0]) - ke_body0,
        "initial_impactor_kinetic_energy_J": ke_body0,
        "internal_work_J": factor * w_int,
        "stored_energy_J": factor * eb["stored_J"],
        "hourglass_energy_J": factor * eb["hourglass_J"],
        "eroded_internal_energy_J": factor * eb["eroded_internal_J"],
        "eroded_hourglass_energy_J": factor * eb["eroded_hourglass_J"],
        "eroded_kinetic_energy_J": factor * eb["eroded_kinetic_J"],
        **({"plastic_work_J": factor * plastic_work(model, state)} if has_metal(model) else {}),
        **(mass_scaling_summary(model, state, factor) if model.mass_scaling_fraction > 0.0
           else {}),
        # undefined (None, "n/a" on the page) while no positive internal work was done,
        # e.g. a spun blade that has only given back part of its pre-stress energy
        "hourglass_fraction": hg_all / w_int if w_int > 0.0 else None,
        "external_work_J": factor * eb["external_work_J"],
        "body_force_work_J": factor * eb["body_force_work_J"],
        "reaction_work_J": factor * eb["reaction_work_J"],
        "contact_energy_J": factor * eb["contact_energy_J"],
        **contact_damping_summary(model, state, factor),
        "eroded_elements": int(np.sum(state.elem[:, SL.E_ALIVE] == 0.0)),
        "energy_error_fraction": error,
        "energy_tolerance": spec.run.energy_tolerance,
        "energy_check": "pass" if error <= spec.run.energy_tolerance else "fail",
        "symmetry_factor": factor,
        # each failing material's element lengths against its calibrated range (theory §1.4)
        MESH_VERDICT_KEY: mesh_verdict(model, state),
        **element_sizes(spec, model),
        "max_displacement_m": float(np.sqrt(np.max(np.sum((state.x - model.x0) ** 2, axis=1)))),
    }


def element_sizes(spec, model) -> dict:
    """summary.json's element sizes (m), the first thing a reader of a result asks:
    ``element_size_m``, the case's ``mesh.element_size`` (a containment casing's: the fine
    sector's in a graded ring) and, for a containment case, ``blade_element_size_m``, the
    blade's (``mesh.blade.element_size``, else the casing's), and
    ``casing_axial_element_size_m`` where ``mesh.casing.axial_element_size`` is given. An imported mesh has no
    such key: there each is the median √(element area) of the elements it stands for
    (the casing layers' and the rest, the blade, in an imported containment mesh), and a
    mesh of hexahedra only (``mesh.kind = "block"`` or imported) has the median
    ∛(hexahedron volume)."""
    mesh = spec.mesh
    if model.n_hexes and not model.n_elems:
        return {"element_size_m": float(np.median(np.cbrt(model.solid.vol0)))}
    if mesh.kind == "plate":
        return {"element_size_m": float(mesh.element_size)}
    if mesh.kind == "containment":
        sizes = {"element_size_m": float(mesh.element_size),
                 "blade_element_size_m": float(mesh.blade_element_size)}
        if mesh.casing.axial_element_size is not None:
            sizes["casing_axial_element_size_m"] = float(mesh.casing.axial_element_size)
        return sizes

    def median_size(elems) -> float | None:
        return float(np.sqrt(np.median(model.area0[elems]))) if len(elems) else None

    if not is_containment(model):
        return {"element_size_m": median_size(np.arange(model.n_elems))}
    casing = np.concatenate(layer_elements(model))
    blade = np.setdiff1d(np.arange(model.n_elems), casing)
    return {"element_size_m": median_size(casing), "blade_element_size_m": median_size(blade)}


def contact_damping_summary(model, state: State, factor: float) -> dict:
    """summary.json keys of the energy the contact dashpots and friction dissipated (J,
    whole problem): in all and per interface, {"layer0-layer1": J, "ply0-impactor": J,
    …} over the interfaces where contact acted (wovenimpact.interfaces; docs/theory.md
    §6, "Contact energy per interface")."""
    books = state.contact_books[0]
    totals = booked_totals(books)
    return {
        "contact_damping_energy_J": factor * totals["damping"],
        "contact_friction_energy_J": factor * totals["friction"],
        "contact_damping_energy_by_interface_J": interface_energies(model, books, DAMPING,
                                                                    factor),
        "contact_friction_energy_by_interface_J": interface_energies(model, books, FRICTION,
                                                                     factor),
    }


def mass_scaling_summary(model, state: State, factor: float) -> dict:
    """summary.json keys of a run with mass scaling: the added mass (whole problem), its
    fraction of the model's mass, the kinetic energy it brought and the elements scaled."""
    row = mass_scaling_row(state)
    return {"added_mass_kg": factor * row["added_mass_part_kg"],
            "added_mass_fraction": row["added_mass_part_kg"] / float(np.sum(model.node_mass)),
            "mass_scaling_energy_J": factor * row["mass_scaling_energy_part_J"],
            "mass_scaled_elements": row["mass_scaled_elements"]}


IMPACT_SUMMARY_KEYS = ("outcome", "perforated", "residual_velocity_m_per_s",
                       "rebound_velocity_m_per_s", "ply_perforated_at_s",
                       "outcome_decided_at_s", "initial_velocity_m_per_s",
                       "absorbed_energy_J", "absorbed_energy_per_ply_J",
                       "contact_work_per_ply_J", "max_deflection_m",
                       "max_deflection_per_ply_m", "peak_contact_force_N")
CONTAINMENT_SUMMARY_KEYS = ("outcome", "contained", "fragment_exit_speed_m_per_s",
                            "fragment_speed_at_end_m_per_s", "fragment_exit_speed_settled", "fragment_mass_kg", "fragment_initial_speed_m_per_s", "max_bulge_m",
                            "casing_mass_kg", "casing_mass_per_area_kg_per_m2", "casing_layers",
                            "absorbed_energy_per_layer_J", "casing_absorbed_energy_J",
                            "held_energy_per_layer_J",
                            "absorbed_energy_per_material_J", "stopped_when_decided",
                            "layer_perforated_at_s", "outcome_decided_at_s",
                            "blade_element_size_m")
COMMON_SUMMARY_KEYS = (
    "summary_version", "case", "end_time_s", "steps", "elements", "nodes", "first_time_step_s",
    "last_time_step_s", "wall_time_s", "element_cycles", "ns_per_element_cycle",
    "structure_kinetic_energy_J", "impactor_kinetic_energy_J", "total_kinetic_energy_J",
    "initial_total_kinetic_energy_J", "initial_structure_kinetic_energy_J",
    "initial_impactor_kinetic_energy_J", "internal_work_J", "stored_energy_J",
    "hourglass_energy_J", "eroded_internal_energy_J", "eroded_hourglass_energy_J",
    "eroded_kinetic_energy_J", "hourglass_fraction", "external_work_J", "body_force_work_J",
    "reaction_work_J", "contact_energy_J", "contact_damping_energy_J",
    "contact_friction_energy_J", "contact_damping_energy_by_interface_J",
    "contact_friction_energy_by_interface_J", "eroded_elements", "energy_error_fraction",
    "energy_tolerance", "energy_check", "symmetry_factor", "max_displacement_m",
    "restarted_from_step", "provenance", "finished_utc", "mesh_verdict", "element_size_m",
    "plastic_work_J",  # runs with a metal section only
    # runs with mass scaling only
    "added_mass_kg", "added_mass_fraction", "mass_scaling_energy_J", "mass_scaled_elements",
)


def summary_keys(spec) -> tuple[str, ...]:
    """The keys summary.json will have for a case (the metrics a study may ask for)."""
    from wovenimpact.spec.case import is_containment_spec

    extra = (CONTAINMENT_SUMMARY_KEYS if is_containment_spec(spec)
             else IMPACT_SUMMARY_KEYS if spec.impactor is not None else ())
    if spec.mesh.kind == "containment" and spec.mesh.casing.axial_element_size is not None:
        extra += ("casing_axial_element_size_m",)  # element_sizes: only where it is given
    return tuple(dict.fromkeys(COMMON_SUMMARY_KEYS + extra))
