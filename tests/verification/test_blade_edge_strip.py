"""The blade-edge strip example (examples/strip/blade_edge_strip.toml; convergence study
V1) runs on its coarsest study mesh: the edge perforates, the energy books close, and the
per-layer contact work accounts for what the edge lost."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from wovenimpact.io.history import read_csv
from wovenimpact.runs import run_case

STRIP = Path(__file__).resolve().parents[2] / "examples" / "strip" / "blade_edge_strip.toml"


def test_the_blade_edge_strip_at_7_mm_perforates_and_its_layers_account_for_the_loss(tmp_path):
    """7 mm elements, to the case's 250 µs: the edge is through the wall (no intact
    material ahead of it; slowed but above 100 m/s — the outcome reads undecided: on this
    mesh torn debris keeps dragging on the edge, docs/validation.md "Blade-edge strip
    (V1)"), the energy balance holds to 1e-3 and the hourglass energy
    stays under 10 % of the internal work (issue 36's acceptance for every study run),
    and the contact work on the five layers is what the edge lost less what the contact
    itself took (its springs' energy and what its dashpots dissipated):
    Σ contact_work_per_ply_J = absorbed_energy_J − contact_energy_J, to 1 % of the
    absorbed energy (the body's and the nodes' work are both trapezoid sums; measured
    −4e-7 relative). The aluminium's absorbed_energy_per_ply_J (held at the end plus its
    plastic work) is what it took through contact within 2 % (measured 64.6 against
    65.2 J; without the plastic work it was 11.4 J); a ply's is less than its contact
    work by the work of its broken yarns, which it does not count."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        s = run_case(STRIP, tmp_path / "o", threads=1, overrides=("mesh.element_size=7 mm",))
    h = read_csv(tmp_path / "o" / "history.csv")
    assert h["intact_material_ahead"][-1] == 0 and s["outcome"] in ("perforated", "undecided")
    assert 100.0 < s["residual_velocity_m_per_s"] < 150.0
    assert s["energy_error_fraction"] < 1e-3 and s["hourglass_fraction"] < 0.1
    work = s["contact_work_per_ply_J"]
    assert len(work) == 5 and len(s["absorbed_energy_per_ply_J"]) == 5
    assert sum(work) == pytest.approx(s["absorbed_energy_J"] - s["contact_energy_J"],
                                      abs=0.01 * s["absorbed_energy_J"])
    per_ply = s["absorbed_energy_per_ply_J"]
    assert per_ply[4] == pytest.approx(work[4], rel=0.02)
    assert all(0.0 < e < w for e, w in zip(per_ply[:4], work[:4]))
