"""history.csv's rows: the columns of a model's history and one row of a State.

A column's name says its scope: ``*_part_J`` energies are of the modelled part (a
quarter of the problem in a quarter model), ``*_full_*`` values (the contact force) of
the whole problem (:func:`history_columns`). The run loop (:mod:`wovenimpact.runs`)
appends a row every ``run.history_interval``; :class:`wovenimpact.io.history.History`
holds and writes them.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.interfaces import booked_totals
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.results.contact_forces import contact_force_columns, contact_force_row
from wovenimpact.results.containment import (
    CASING_ENERGY_COLUMNS,
    CONTAINMENT_COLUMNS,
    CasingWatch,
    casing_energy_row,
    fragment_row,
    is_containment,
    layer_columns,
    layer_row,
    layer_sets,
)
from wovenimpact.results.energy import energy_balance, error_fraction
from wovenimpact.results.metal_state import has_metal, plastic_work
from wovenimpact.results.quantities import (
    REACTION_COLUMNS,
    impactor_row,
    intact_material_ahead,
    ply_columns,
    ply_row,
    reaction_row,
)
from wovenimpact.state import MASS_SCALING, State

HISTORY_COLUMNS = (
    "time_s", "step", "dt_s", "structure_kinetic_energy_part_J", "internal_work_part_J",
    "stored_energy_part_J", "hourglass_energy_part_J", "external_work_part_J",
    "eroded_kinetic_energy_part_J", "eroded_internal_energy_part_J", "contact_energy_part_J",
    "contact_dissipated_part_J", "contact_damping_energy_part_J",
    "contact_friction_energy_part_J", "body_force_work_part_J", "reaction_work_part_J",
    "energy_drift_part_J", "energy_error_fraction", "energy_normaliser_part_J",
    "max_displacement_m", "eroded_elements",
)
IMPACT_COLUMNS = ("impactor_velocity_m_per_s", "impactor_displacement_m", "contact_force_full_N",
                  "impactor_nose_ahead_of_intact_m", "intact_material_ahead",
                  "impactor_kinetic_energy_part_J")
METAL_COLUMNS = ("plastic_work_part_J",)  # models with a J2 (metal) section
MASS_SCALING_COLUMNS = ("added_mass_part_kg", "mass_scaling_energy_part_J", "mass_scaled_elements")


def history_columns(model) -> tuple[str, ...]:
    """history.csv columns: energies etc., plus the impactor's if there is one.

    Scope in the name: ``*_part_J`` is of the modelled part (a quarter of the problem
    in a quarter model; × ``symmetry_factor`` of summary.json gives the whole), ``*_full_*``
    of the whole problem; velocities, displacements, fractions and counts need neither.
    ``energy_drift_part_J`` is the balance's drift (results.energy.energy_balance),
    ``energy_normaliser_part_J`` the largest energy put into the model so far (the running
    maximum of its ``scale_J`` over the rows up to this one) and ``energy_error_fraction``
    = |drift| / normaliser (0 while the normaliser is 0: no energy put in); summary.json's
    figure is the largest |drift| over the last (largest) normaliser.
    ``body_force_work_part_J`` and ``reaction_work_part_J`` (supports and prescribed
    motions) are the two parts of ``external_work_part_J``.
    ``contact_energy_part_J`` is −(work of the contact forces): the penalty springs' energy
    plus ``contact_dissipated_part_J``, what contact dashpots and friction dissipated;
    of it, ``contact_damping_energy_part_J`` and ``contact_friction_energy_part_J`` are
    the dashpots' and friction's own work, booked pair by pair (wovenimpact.interfaces;
    the rest is the penalty's discretisation: k follows Δt, docs/theory.md §6).
    ``plastic_work_part_J`` (models with a metal section): the plastic work of the J2
    points (metal_state.plastic_work), a part of the internal work. With mass scaling
    (``run.mass_scaling_fraction``): ``added_mass_part_kg``, ``mass_scaling_energy_part_J``
    (the kinetic energy the added mass brought, an input of the balance) and
    ``mass_scaled_elements``. A containment model's rows add the fragment's and the
    casing's columns (containment.fragment_row, containment.casing_energy_row: the
    fragment's kinetic energy and the casing's kinetic, element and absorbed energies).

    Last come the columns of each layer or ply (appended after all the others, so the
    columns before them keep their places): a containment model's
    ``casing_layer{k}_absorbed_energy_part_J`` and ``casing_layer{k}_intact_outside``
    (containment.layer_row), a plate impact's ``ply{p}_contact_work_part_J`` and
    ``ply{p}_intact_ahead`` (quantities.ply_row). After them, appended later still,
    ``reaction_force_{x,y,z}_part_N``: the summed reaction force of the supports (nodes with
    all three translations fixed) in global axes, the force whose work
    ``reaction_work_part_J`` books (quantities.support_reaction). Last, the contact force
    between the blade and the casing and between consecutive layers or plies
    (results.contact_forces: ``contact_force_blade_casing_N``,
    ``contact_force_layer{k}_layer{k+1}_N``, ``contact_force_ply{p}_ply{q}_full_N``)."""
    return (HISTORY_COLUMNS + (IMPACT_COLUMNS if model.body_params.shape[0] else ())
            + (METAL_COLUMNS if has_metal(model) else ())
            + (MASS_SCALING_COLUMNS if model.mass_scaling_fraction > 0.0 else ())
            + (CONTAINMENT_COLUMNS + CASING_ENERGY_COLUMNS if is_containment(model) else ())
            + per_layer_columns(model) + REACTION_COLUMNS + contact_force_columns(model))


def per_layer_columns(model) -> tuple[str, ...]:
    """The layer or ply columns ending a history row (:func:`history_columns`)."""
    if is_containment(model):
        return layer_columns(len(layer_sets(model)))
    if model.body_params.shape[0]:
        return ply_columns(model)
    return ()


def history_row(model, state: State, normaliser: float = 0.0,
                watch: CasingWatch | None = None, contact=None) -> dict:
    """One history.csv row of ``state`` (columns :func:`history_columns`); ``normaliser``
    is the previous row's ``energy_normaliser_part_J`` (0 for the first row); ``watch``
    the run's :class:`~wovenimpact.results.containment.CasingWatch` (containment models; made
    for the row when not given); ``contact`` the step's contact buffers
    (``Workspace.contact``), whose last forces give the interface force columns (zeros
    without: before the first step)."""
    eb = energy_balance(model, state)
    booked = booked_totals(state.contact_books[0])
    scale = max(normaliser, eb["scale_J"])
    disp = np.sqrt(np.max(np.sum((state.x - model.x0) ** 2, axis=1)))
    impact = {}
    if model.body_params.shape[0]:
        impact = {**impactor_row(model, state), **intact_material_ahead(model, state),
                  "impactor_kinetic_energy_part_J": eb["impactor_kinetic_J"]}
    if is_containment(model):
        watch = CasingWatch(model) if watch is None else watch
        impact.update(fragment_row(model, state, watch))
        impact.update(casing_energy_row(model, state, watch))
        impact.update(layer_row(model, state, watch))
    elif model.body_params.shape[0]:
        impact.update(ply_row(model, state))
    if has_metal(model):
        impact["plastic_work_part_J"] = plastic_work(model, state)
    if model.mass_scaling_fraction > 0.0:
        impact.update(mass_scaling_row(state))
    impact.update(reaction_row(model, state))
    impact.update(contact_force_row(model, contact))
    return {
        **impact,
        "time_s": float(state.t), "step": int(state.step), "dt_s": float(state.dt),
        "structure_kinetic_energy_part_J": eb["kinetic_J"],
        "internal_work_part_J": eb["internal_work_J"], "stored_energy_part_J": eb["stored_J"],
        "hourglass_energy_part_J": eb["hourglass_J"],
        "external_work_part_J": eb["external_work_J"],
        "eroded_kinetic_energy_part_J": eb["eroded_kinetic_J"],
        "eroded_internal_energy_part_J": eb["eroded_internal_J"],
        "contact_energy_part_J": eb["contact_energy_J"],
        "contact_dissipated_part_J": eb["contact_dissipated_J"],
        "contact_damping_energy_part_J": booked["damping"],
        "contact_friction_energy_part_J": booked["friction"],
        "body_force_work_part_J": eb["body_force_work_J"],
        "reaction_work_part_J": eb["reaction_work_J"], "energy_drift_part_J": eb["drift_J"],
        "energy_error_fraction": error_fraction(eb["drift_J"], scale),
        "energy_normaliser_part_J": scale, "max_displacement_m": float(disp),
        "eroded_elements": int(np.sum(state.elem[:, SL.E_ALIVE] == 0.0)),
    }


def mass_scaling_row(state: State) -> dict:
    """Mass added by mass scaling so far (modelled part), the kinetic energy it brought
    and the number of elements that carry some."""
    return {"added_mass_part_kg": float(np.sum(state.added_mass)),
            "mass_scaling_energy_part_J": float(state.energy[MASS_SCALING]),
            "mass_scaled_elements": int(np.count_nonzero(state.mass_ratio))}
