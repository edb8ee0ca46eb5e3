"""The column and code constants of the layout modules cannot be confused across modules
(issue 13): a public UPPERCASE name is defined by one layout module only, apart from the
names listed below, each with the reason it is shared.

A name counts where it is assigned at the top level of a module's source (a name that
module imports from another, like kernels/fabric_table.py's, is not its definition).
"""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
TESTS = Path(__file__).resolve().parents[1]

# every module that lays out a table's columns or a set of codes
LAYOUT_MODULES = (
    "wovenimpact.kernels.shell_layout",  # sections, element state, material kinds, EL_*
    "wovenimpact.kernels.fabric_layout",  # crossover parameter and point-state vectors
    "wovenimpact.kernels.j2_layout",  # J2 parameter and point-state vectors
    "wovenimpact.kernels.solid_layout",  # hexahedron state H_*, transversely isotropic TI_*
    "wovenimpact.kernels.rigid_body",  # body state B_* and parameters BP_*
    "wovenimpact.kernels.contact_narrow",  # pair table GEO_*, segment table SG_*
    "wovenimpact.kernels.integrate",  # boundary-condition codes
    "wovenimpact.state",  # State.energy indices
)

# Same name, same value, same meaning, on purpose: a section kernel reads a fabric and a
# J2 point alike (shell.point_response reads FL.S_ALIVE / FL.S_ENERGY for both kinds and
# treats the point kernels' return codes alike).
SHARED_SAME_VALUE = {
    "S_ALIVE": "a point's alive flag, one column for every material kind",
    "S_ENERGY": "a point's stored energy per reference area, one column for every kind",
    "STATUS_OK": "the point kernels' return codes, one set for every kind",
    "STATUS_NOT_CONVERGED": "the point kernels' return codes, one set for every kind",
    "STATUS_BAD_KINEMATICS": "the point kernels' return codes, one set for every kind",
}
# Same role, each layout's own value: the length of its own vector, and the texts of the
# shared status codes worded for its material. Always read through the module
# (FL.N_STATE, J.N_STATE), never imported bare where two kinds meet.
SHARED_OWN_VALUE = {
    "N_PARAM": "length of the module's own parameter vector",
    "N_STATE": "length of the module's own point-state vector",
    "STATUS_TEXT": "the module's wording of the shared STATUS_* codes",
}


def defined_constants(module_name: str) -> dict[str, object]:
    """Public UPPERCASE names assigned at the top level of the module's source, with their
    values (from the imported module)."""
    module = importlib.import_module(module_name)
    tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
    names = []
    for node in tree.body:
        targets = (node.targets if isinstance(node, ast.Assign)
                   else [node.target] if isinstance(node, ast.AnnAssign) else [])
        for target in targets:
            elts = target.elts if isinstance(target, ast.Tuple) else [target]
            names += [e.id for e in elts if isinstance(e, ast.Name)]
    return {n: getattr(module, n) for n in names if n.isupper() and not n.startswith("_")}


def definitions() -> dict[str, dict[str, object]]:
    """name → {module: value} over the layout modules."""
    out: dict[str, dict[str, object]] = {}
    for m in LAYOUT_MODULES:
        for name, value in defined_constants(m).items():
            out.setdefault(name, {})[m] = value
    return out


def test_no_two_layout_modules_define_the_same_name_unless_listed():
    shared = {n: mods for n, mods in definitions().items() if len(mods) > 1}
    unlisted = {n: sorted(mods) for n, mods in shared.items()
                if n not in SHARED_SAME_VALUE and n not in SHARED_OWN_VALUE}
    assert not unlisted, f"names defined by more than one layout module: {unlisted}"


def test_names_shared_on_purpose_have_one_value():
    defs = definitions()
    for name in SHARED_SAME_VALUE:
        values = set(defs[name].values())
        assert len(values) == 1, f"{name} differs between {sorted(defs[name])}: {values}"


@pytest.mark.parametrize("name", sorted({**SHARED_SAME_VALUE, **SHARED_OWN_VALUE}))
def test_the_allow_lists_hold_only_names_that_are_shared(name):
    assert len(definitions().get(name, {})) > 1, f"{name} is no longer shared: drop it"


def test_elastic_columns_do_not_wear_the_element_state_prefix():
    """``E_*`` are element-state columns only; the elastic parameter row has its own names
    (they were ``E_MOD``, ``E_NU``, ``E_RHO`` at columns 0–2, the values of ``E_F`` …)."""
    from wovenimpact.kernels import shell_layout as SL

    assert not {"E_MOD", "E_NU", "E_RHO"} & set(vars(SL))
    assert (SL.ELASTIC_MODULUS, SL.ELASTIC_POISSON, SL.ELASTIC_DENSITY) == (0, 1, 2)


def test_shell_layout_is_not_imported_as_S():
    """``S`` read like the ``S_*`` point-state columns beside it: shell_layout is ``SL``."""
    pattern = re.compile(r"import\s+shell_layout\s+as\s+S\b")
    found = [str(p) for root in (SRC, TESTS) for p in root.rglob("*.py")
             if pattern.search(p.read_text(encoding="utf-8"))]
    assert not found, found
