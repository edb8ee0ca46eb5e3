"""How far a run's failure can be trusted on its mesh: each failing material's element
lengths against the range its failure law was calibrated for (docs/theory.md §1.4, §7.3).

A material whose failure is not regularised (no ``[material.regularisation]`` table)
holds its answers only on elements of its reference length (a fabric: the crossover
cell, 2ℓ0; a metal: none given, so any size is outside it); a regularised one within
the lengths its table was calibrated on (the table's first and last rows). The lengths
judged are those of the material's elements that failed (eroded) in the run — not a
blade's release row, which is let go — or all of its elements if none did: a contained or
stopped run is judged by where it could have failed.

A failure law calibrated on elements of one size cannot make up for a contact the mesh
does not resolve: a striker's edge of radius R (a blade's edge, half its thickness; a
projectile's rim fillet; Impactor.edge_radius) is felt as a blunter one by elements much
larger than R, which then take more energy before they fail (docs/theory.md §8.8:
the blade-edge strip and the blunt projectile's ladder). Each struck material's verdict
therefore also says whether its judged elements are at most ``RESOLVED_FRACTION`` × R —
a necessary condition for an answer that holds when the mesh is refined, not a
sufficient one.

A metal casing has a third length: a cylinder of radius R and wall t loaded radially bends
along its axis within ℓ = √(R t)/[3(1 − ν²)]^{1/4} (its bending boundary layer), and a
ring's answer follows its elements' edge along the axis (docs/theory.md §8.8: the 1 mm
aluminium ring's share of a fragment's energy is 38 % above its extrapolated value on
7 mm elements, 5 % on 1 mm along the axis). Each metal material of a casing layer
(element sets ``casing.layer{k}``) is therefore judged also on whether its longest edge
along the axis is at most ``BENDING_FRACTION`` × ℓ — measured on one ring (R = 250 mm,
t = 1 mm); that the length scales with √(R t) is shell theory's, not yet measured.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import j2_layout as JL
from wovenimpact.kernels import shell_layout as SL

REFERENCE_TOLERANCE = 0.1  # an unregularised law: elements within 10 % of its reference length
RESOLVED_FRACTION = 0.5  # elements up to half the striker's edge radius resolve its contact
BENDING_FRACTION = 0.1  # a casing's axial edge up to ℓ/10 resolves its bending boundary layer
SUMMARY_KEY = "mesh_verdict"


def _law(model, m: int):
    """(reference lengths (k,), the calibrated range of l/l_ref (2,) or None, the lengths
    (n, k) of the n elements of material m, and those elements) — k = 2 yarn families for
    a fabric, 1 for a metal. A metal without a reference length gets reference 0 (every
    size outside)."""
    p = model.mat_params[m]
    elems = np.flatnonzero(model.sections[model.elem_section, SL.C_MAT] == m)
    if model.mat_kind[m] == SL.MAT_FABRIC:
        ref = p[FL.P_REG_LENGTH:FL.P_REG_LENGTH + 2]
        rows = int(p[FL.P_REG_ROWS])
        table = p[FL.P_REG_TABLE:FL.P_REG_TABLE + 2 * rows:2]
        lengths = model.elem_length[elems]
    else:
        ref = p[JL.P_FRAC_LENGTH:JL.P_FRAC_LENGTH + 1]
        rows = int(p[JL.P_FRAC_ROWS])
        table = p[JL.P_FRAC_TABLE:JL.P_FRAC_TABLE + 2 * rows:2]
        lengths = model.elem_length[elems, :1]
    calibrated = np.array([table.min(), table.max()]) if rows else None
    return ref, calibrated, lengths, elems


def fails(model, m: int) -> bool:
    """Whether material m has a failure law at all (a fabric always; a J2 metal with a
    fracture strain or Johnson–Cook damage; an elastic one never)."""
    kind = model.mat_kind[m]
    if kind == SL.MAT_FABRIC:
        return True
    if kind == SL.MAT_J2:
        p = model.mat_params[m]
        return bool(p[JL.P_FRACTURE] > 0.0 or p[JL.P_DAMAGE] != 0.0)
    return False


def casing_bending(model, m: int):
    """(the bending length ℓ (m), the longest edge along the z axis (m)) of material m's
    elements in a casing's layers (element sets ``casing.layer{k}``), or None: a cylinder
    about z of radius R (the elements' mean distance from the axis) and wall t (their
    section's), ℓ = √(R t)/[3(1 − ν²)]^{1/4} (Timoshenko and Woinowsky-Krieger, Theory
    of Plates and Shells, §114). Metals only: a fabric ply has no bending stiffness of
    its own to make a boundary layer."""
    if model.mat_kind[m] not in (SL.MAT_J2, SL.MAT_ELASTIC):
        return None
    sets = [np.asarray(e, dtype=np.int64) for name, e in model.elem_sets.items()
            if name.startswith("casing.layer")]
    if not sets:
        return None
    elems = np.unique(np.concatenate(sets))
    elems = elems[model.sections[model.elem_section[elems], SL.C_MAT] == m]
    if not elems.size:
        return None
    x = model.x0[model.quads[elems]]  # (n, 4, 3)
    radius = float(np.mean(np.hypot(x[:, :, 0], x[:, :, 1])))
    thickness = float(np.max(model.sections[model.elem_section[elems], SL.C_THICK]))
    nu = float(model.mat_params[m, 1])
    length = np.sqrt(radius * thickness) / (3.0 * (1.0 - nu * nu)) ** 0.25
    axial = float(np.max(x[:, :, 2].max(axis=1) - x[:, :, 2].min(axis=1)))
    return float(length), axial


def mesh_verdict(model, state) -> dict:
    """Per failing material (by its name): the element lengths judged (mm, smallest and
    largest), the reference length (mm), the calibrated range (mm, or None), whether any
    of its elements failed, and the verdict — "at the reference size", "within the
    calibrated range", "coarser than the calibrated range", "finer than the calibrated
    range" or "not regularised" — with ``ok`` True for the first two."""
    out = {}
    if model.elem_length.shape[0] != model.n_elems:
        return out
    eroded = state.elem[:, SL.E_ALIVE] == 0.0
    eroded[model.release_elems] = False  # a blade's release row is let go, not failed
    radius = model.striking_radius
    striker_mats = {int(model.sections[model.elem_section[e], SL.C_MAT])
                    for e in model.release_elems[:1]}  # a blade is not struck by itself
    for m in range(len(model.mat_kind)):
        if not fails(model, m):
            continue
        ref, calibrated, lengths, elems = _law(model, m)
        if not elems.size:
            continue
        failed = eroded[elems]
        judged = lengths[failed] if failed.any() else lengths
        lo, hi = float(judged.min()), float(judged.max())
        ratio_lo = judged.min(axis=0) / np.where(ref > 0.0, ref, np.inf)
        ratio_hi = judged.max(axis=0) / np.where(ref > 0.0, ref, np.inf)
        if calibrated is not None:
            if np.all(ratio_lo >= calibrated[0] * (1.0 - 1e-9)) and np.all(
                    ratio_hi <= calibrated[1] * (1.0 + 1e-9)):
                verdict, ok = "within the calibrated range", True
            elif np.any(ratio_hi > calibrated[1]):
                verdict, ok = "coarser than the calibrated range", False
            else:
                verdict, ok = "finer than the calibrated range", False
            span = [float(calibrated[0] * ref.min() * 1e3), float(calibrated[1] * ref.max() * 1e3)]
        else:
            span = None
            near = np.all(ref > 0.0) and np.all(np.abs(ratio_lo - 1.0) <= REFERENCE_TOLERANCE) \
                and np.all(np.abs(ratio_hi - 1.0) <= REFERENCE_TOLERANCE)
            verdict, ok = ("at the reference size", True) if near else ("not regularised", False)
        name = model.material_names[m] or f"material {m}"
        resolved = None  # no striker, or the striker's own material
        if np.isfinite(radius) and m not in striker_mats:
            resolved = bool(hi <= RESOLVED_FRACTION * radius * (1.0 + 1e-9))
            ok = ok and resolved
        bending = casing_bending(model, m)
        bending_resolved = None  # not a metal casing layer
        if bending is not None:
            bending_resolved = bool(bending[1] <= BENDING_FRACTION * bending[0] * (1.0 + 1e-9))
            ok = ok and bending_resolved
        out[name] = {
            "element_length_mm": [lo * 1e3, hi * 1e3],
            "reference_length_mm": float(ref.max() * 1e3) if np.any(ref > 0.0) else None,
            "calibrated_range_mm": span,
            "judged_on": "eroded elements" if failed.any() else "all its elements",
            "verdict": verdict,
            "striking_radius_mm": radius * 1e3 if np.isfinite(radius) else None,
            "striker_resolved": resolved,
            "casing_bending_length_mm": None if bending is None else bending[0] * 1e3,
            "casing_axial_edge_mm": None if bending is None else bending[1] * 1e3,
            "casing_bending_resolved": bending_resolved,
            "ok": bool(ok),
        }
    return out


def verdict_text(verdicts: dict) -> tuple[str, bool | None]:
    """One line for the report's mesh box, and whether every material passed (None
    when no material can fail)."""
    if not verdicts:
        return "no failing material", None
    parts = []
    for name, v in verdicts.items():
        lo, hi = v["element_length_mm"]
        size = f"{lo:.3g} mm" if abs(hi - lo) <= 1e-6 * hi else f"{lo:.3g}–{hi:.3g} mm"
        ref = v["calibrated_range_mm"] or (
            [v["reference_length_mm"]] * 2 if v["reference_length_mm"] else None)
        against = "" if ref is None else (
            f" (calibrated {ref[0]:.3g}–{ref[1]:.3g} mm)" if v["calibrated_range_mm"]
            else f" (reference {ref[0]:.3g} mm)")
        edge = ""
        if v.get("striker_resolved") is not None:
            r = v["striking_radius_mm"]
            edge = (f"; the striker's edge (radius {r:.3g} mm) resolved" if v["striker_resolved"]
                    else "; struck by a sharp edge (radius 0), which no mesh resolves: give "
                    "the impactor a fillet" if r == 0.0
                    else f"; coarser than half the striker's edge radius ({r:.3g} mm): its "
                    "contact is not resolved")
        if v.get("casing_bending_resolved") is not None:
            a, ell = v["casing_axial_edge_mm"], v["casing_bending_length_mm"]
            edge += (f"; {a:.3g} mm along the casing's axis, its bending length {ell:.3g} mm "
                     + ("resolved" if v["casing_bending_resolved"] else
                        f"not resolved (needs ≤ {BENDING_FRACTION * ell:.3g} mm: "
                        "mesh.casing.axial_element_size)"))
        parts.append(f"{name}: {size}, {v['verdict']}{against}{edge}")
    return "; ".join(parts), all(v["ok"] for v in verdicts.values())
