"""Shell–shell contact on imported meshes: which shells meet (`[contact] surfaces`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from wovenimpact.setup.compile import compile_case
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.spec.case import load_case

ROOT = Path(__file__).resolve().parents[2]
N = 4  # elements per side of a layer
SIZE = 1e-3  # element size (m)
THICK = 0.5e-3
GAP = 0.6e-3  # mid-plane distance: the layers start 0.1 mm apart


def two_layer_inp(path: Path, one_set: bool) -> Path:
    """Two square layers of N × N S4R elements, each on its own nodes (two connected
    parts), z = 0 and z = GAP; element sets LOW and HIGH (or ALL if ``one_set``)."""
    lines = ["*HEADING", "two layers", "*NODE"]
    per = (N + 1) ** 2
    for layer in range(2):
        for j in range(N + 1):
            for i in range(N + 1):
                k = layer * per + j * (N + 1) + i + 1
                lines.append(f"{k}, {i * SIZE}, {j * SIZE}, {layer * GAP}")
    for layer, name in enumerate(("LOW", "HIGH")):
        lines.append(f"*ELEMENT, TYPE=S4R, ELSET={'ALL' if one_set else name}")
        for j in range(N):
            for i in range(N):
                a = layer * per + j * (N + 1) + i + 1
                e = layer * N * N + j * N + i + 1
                lines.append(f"{e}, {a}, {a + 1}, {a + N + 2}, {a + N + 1}")
    lines += ["*NSET, NSET=HIGHNODES, GENERATE", f"{per + 1}, {2 * per}, 1"]
    path.write_text("\n".join(lines) + "\n")
    return path


def run_layers(tmp_path: Path, surfaces: str, one_set: bool = False) -> tuple[float, dict]:
    """The high layer thrown at the free low one at 50 m/s for 20 µs (1 mm of travel
    from 0.6 mm above it, if nothing stops it): the smallest
    distance between their mid-planes (over the run) and the energy balance."""
    two_layer_inp(tmp_path / "layers.inp", one_set)
    sets = '{ ALL = "plate" }' if one_set else '{ LOW = "plate", HIGH = "plate" }'
    case = tmp_path / "layers.toml"
    case.write_text(f"""
[case]
name = "two imported layers"
[materials]
steel = "{(ROOT / 'examples' / 'materials' / 'steel.toml').as_posix()}"
[sections.plate]
material = "steel"
thickness = "{THICK * 1e3} mm"
[mesh]
kind = "abaqus"
file = "layers.inp"
sections = {sets}
[contact]
surfaces = "{surfaces}"
[[initial_velocity]]
nodes = "HIGHNODES"
velocity = ["0 m/s", "0 m/s", "-50 m/s"]
[run]
end_time = "20 us"
""")
    compiled = compile_case(*load_case(case))
    model, st = compiled.model, compiled.state
    ws = Workspace.for_model(model, st)
    per = (N + 1) ** 2
    closest = np.inf
    while st.t < 20e-6:
        step(model, st, ws)
        closest = min(closest, float(np.min(st.x[per:, 2] - st.x[:per, 2])))
    return closest, energy_balance(model, st)


@pytest.mark.parametrize("surfaces", ["parts", "plies", "element_sets"])
def test_imported_layers_meet_as_separate_surfaces(tmp_path, surfaces):
    """Two layers of an imported mesh, each on its own nodes: as connected parts (the
    default for imported meshes, also under "plies") or as element sets LOW/HIGH they
    are two surfaces and the thrown layer stops on the other — their mid-planes never
    come closer than a shell thickness less the penalty's small penetration — and the
    energy balance holds (dashpot dissipation booked in the contact energy)."""
    closest, eb = run_layers(tmp_path, surfaces)
    assert THICK * 0.9 < closest
    assert eb["contact_energy_J"] > 0.0
    assert eb["error_fraction"] < 1e-3


def test_without_surfaces_or_in_one_element_set_the_layers_pass_through(tmp_path):
    """The same layers with surfaces = "none", or both in one element set under
    "element_sets", are one surface: nothing stops the thrown layer, which passes
    through the other (the distance goes negative)."""
    (tmp_path / "none").mkdir()
    closest, _ = run_layers(tmp_path / "none", "none")
    assert closest < 0.0
    (tmp_path / "one").mkdir()
    closest, _ = run_layers(tmp_path / "one", "element_sets", one_set=True)
    assert closest < 0.0
