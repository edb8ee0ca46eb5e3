"""Write the acceptance corpus of bad inputs (issue 12) into a directory.

Every item is one command line (``wovenimpact …``) on files written here from the
examples: small, sane base cases (a 10 mm quarter plate, 2 µs) with one thing made
wrong — a case, material, study, mesh (.inp/.msh) or calibration CSV file, or a flag.
Each item is labelled with what a user should get:

- ``error``: a clean error (exit code 2, ``error: …`` naming the file/key/value);
- ``warn``: a run that finishes with a named ``warning: …`` (or a clean error);
- ``ok``: a control, a sane input that must run (guards against refusing good input).

``python -m tests.corpus.runner`` runs them and classifies each result.
"""

from __future__ import annotations

import json
import math
import shutil
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SHORT = "run.end_time=2 us"  # sane runs stay short


@dataclass
class Item:
    """One corpus entry: its id, the CLI arguments, the expected class and a note."""

    id: str
    argv: list[str]
    expect: str  # error | warn | ok
    kind: str  # case | material | study | mesh | csv | flag
    note: str = ""
    timeout: float = 60.0
    files: dict[str, bytes] = field(default_factory=dict, repr=False)
    warns: str = ""  # a ``warn`` item: what its warning must say


# what the warning of each ``warn`` item must contain (by the item's id suffix)
WARNS = {"areal_mass_1e30": "areal_mass", "areal_mass_x100": "areal_mass",
         "end_time_1e-30": "shorter than the first step",
         "no_boundary_quarter": "no boundary constrains", "threads_1000": "threads",
         "a_metre_away": "reaches it at", "velocity_1e-30": "reaches it at",
         # issue 12 item 5: the same value twice in a sweep runs that variant once
         "study_duplicate_values": "1 of the 2 variants repeat the values of another"}


# --- a small TOML writer (the corpus writes documents it then breaks) ------------------


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(v)


def dumps(doc: dict, prefix: str = "") -> str:
    """TOML text of ``doc`` (tables, arrays of tables, inline values)."""
    lines, tables = [], []
    for k, v in doc.items():
        key = json.dumps(k) if not k.replace("_", "").isalnum() else k
        full = f"{prefix}.{key}" if prefix else key
        if isinstance(v, dict) and v and not _inline(prefix, k):
            tables.append((full, v, False))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            tables.append((full, v, True))
        else:
            lines.append(f"{key} = {_value(v)}")
    out = "\n".join(lines) + ("\n" if lines else "")
    for full, v, array in tables:
        if array:
            for item in v:
                out += f"\n[[{full}]]\n" + dumps(item, full)
        else:
            out += f"\n[{full}]\n" + dumps(v, full)
    return out


def _inline(prefix: str, key: str) -> bool:
    """Tables written inline: material references with a ``set`` and section maps."""
    return prefix == "materials" or key in ("set", "sections") and prefix == "mesh"


# --- base documents -------------------------------------------------------------------

PLATE = {
    "case": {"name": "corpus plate"},
    "materials": {"kevlar": "kevlar.toml"},
    "sections": {"fabric": {"material": "kevlar", "bending_modulus": "1 GPa",
                            "transverse_shear_modulus": "3.28 GPa"}},
    "mesh": {"kind": "plate", "side": "10 mm", "element_size": "0.94 mm", "quarter": True,
             "section": "fabric"},
    "boundary": [{"nodes": "edge_outer", "type": "clamped"},
                 {"nodes": "symmetry_x", "type": "symmetry_x"},
                 {"nodes": "symmetry_y", "type": "symmetry_y"}],
    "initial_velocity": [{"velocity": ["0 m/s", "0 m/s", "-50 m/s"], "radius": "1.5 mm"}],
    "run": {"end_time": "2 us", "history_interval": "0.5 us"},
}

IMPACT = {k: v for k, v in PLATE.items() if k != "initial_velocity"} | {
    "case": {"name": "corpus impact"},
    "mesh": PLATE["mesh"] | {"plies": 2, "spacing": "0.4992 mm"},  # touching plies
    "impactor": {"shape": "cylinder", "radius": "2.78 mm", "length": "5.72 mm",
                 "mass": "1.1 g", "position": ["0 mm", "0 mm", "0.85 mm"],
                 "direction": [0, 0, -1], "velocity": "120 m/s"},
}

METAL = PLATE | {
    "case": {"name": "corpus metal plate"},
    "materials": {"al": "aluminium.toml"},
    "sections": {"sheet": {"material": "al", "thickness": "1 mm"}},
    "mesh": PLATE["mesh"] | {"element_size": "1 mm", "section": "sheet"},
    "initial_velocity": [{"velocity": ["0 m/s", "0 m/s", "-20 m/s"], "radius": "2 mm"}],
}

INP_CASE = {
    "case": {"name": "corpus abaqus"},
    "materials": {"kevlar": "kevlar.toml"},
    "sections": {"fabric": {"material": "kevlar", "bending_modulus": "1 GPa",
                            "transverse_shear_modulus": "3.28 GPa"}},
    "mesh": {"kind": "abaqus", "file": "plate.inp", "sections": {"plate": "fabric"}},
    "boundary": [{"nodes": "edge", "type": "clamped"}],
    "initial_velocity": [{"velocity": ["0 m/s", "0 m/s", "-20 m/s"]}],
    "run": {"end_time": "2 us", "history_interval": "0.5 us"},
}


def plate_inp(n: int = 3, h: float = 0.001, dup_node: bool = False, dup_elem: bool = False,
              nan: bool = False, missing_node: bool = False, etype: str = "S4R",
              degenerate: bool = False) -> str:
    """An n×n S4R plate of h-sized quads with sets ``plate`` and ``edge``."""
    lines = ["*HEADING", "corpus plate", "*NODE"]
    nid = {}
    for j in range(n + 1):
        for i in range(n + 1):
            k = j * (n + 1) + i + 1
            nid[i, j] = k
            x = "nan" if nan and k == 5 else f"{i * h:.6g}"
            lines.append(f"{k}, {x}, {j * h:.6g}, 0.0")
    if dup_node:
        lines.append("1, 0.5, 0.5, 0.0")
    lines.append(f"*ELEMENT, TYPE={etype}")
    e = 1
    for j in range(n):
        for i in range(n):
            q = [nid[i, j], nid[i + 1, j], nid[i + 1, j + 1], nid[i, j + 1]]
            if degenerate and e == 1:
                q = [q[0], q[0], q[0], q[0]]
            if missing_node and e == 1:
                q[2] = 9999
            lines.append(f"{e}, " + ", ".join(map(str, q)))
            e += 1
    if dup_elem:
        lines.append(f"1, {nid[0, 0]}, {nid[1, 0]}, {nid[1, 1]}, {nid[0, 1]}")
    lines.append("*ELSET, ELSET=plate, GENERATE")
    lines.append(f"1, {n * n}, 1")
    edge = sorted({nid[i, j] for (i, j) in nid if i in (0, n) or j in (0, n)})
    lines.append("*NSET, NSET=edge")
    lines.append(", ".join(map(str, edge)))
    return "\n".join(lines) + "\n"


STUDY = {
    "study": {"name": "corpus study", "case": "plate.toml", "combine": "grid",
              "metrics": ["max_displacement_m", "energy_error_fraction"]},
    "parameters": {"initial_velocity.0.velocity": [["0 m/s", "0 m/s", "-40 m/s"]]},
}

CSV = (EXAMPLES / "calibration" / "compression_synthetic.csv").read_text()


def _copy(doc):
    return json.loads(json.dumps(doc))


def _set(doc: dict, key: str, value) -> dict:
    """A copy of ``doc`` with the dotted ``key`` set (``None`` deletes it)."""
    doc = _copy(doc)
    parts = key.split(".")
    node = doc
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif value is None:
        node.pop(last, None)
    else:
        node[last] = value
    return doc


# --- the items ------------------------------------------------------------------------


class Corpus:
    """Collects items and the files they need (written by :meth:`write`)."""

    def __init__(self):
        self.items: list[Item] = []
        self.files: dict[str, bytes] = {}

    def file(self, name: str, content: str | bytes | dict) -> str:
        if isinstance(content, dict):
            content = dumps(content)
        if isinstance(content, str):
            content = content.encode("utf-8")
        self.files[name] = content
        return name

    def add(self, id: str, argv: list[str], expect: str, kind: str, note: str = "",
            timeout: float = 60.0) -> None:
        assert id not in {i.id for i in self.items}, id
        if expect == "ok":  # the controls run first and may compile the kernels
            timeout = 1800.0
        warns = next((w for k, w in WARNS.items() if id.endswith(k)), "")
        assert (expect == "warn") == bool(warns), id
        self.items.append(Item(id, argv, expect, kind, note, timeout, warns=warns))

    def run_case(self, id: str, doc_or_name, expect: str = "error", note: str = "",
                 extra=(), kind: str = "case", short: bool = False) -> None:
        name = doc_or_name if isinstance(doc_or_name, str) else self.file(f"{id}.toml",
                                                                            doc_or_name)
        sets = ["--set", SHORT] if short else []
        self.add(id, ["run", name, "--out", f"out/{id}", "--json", *sets, *extra], expect,
                 kind, note)

    def write(self, root: Path) -> None:
        root.mkdir(parents=True, exist_ok=True)
        for name, data in self.files.items():
            path = root / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        (root / "an_existing_file").write_text("not a directory\n")
        shutil.rmtree(root / "out", ignore_errors=True)
        (root / "out").mkdir()


BAD_VALUES = [  # (label, value-maker from a good unit) for quantity keys
    ("nounit", lambda u: "12"),
    ("wrongdim", lambda u: "12 kg*s"),
    ("negative", lambda u: f"-3 {u}"),
    ("nan", lambda u: f"nan {u}"),
    ("inf", lambda u: f"inf {u}"),
    ("text", lambda u: "about twelve"),
    ("bool", lambda u: True),
    ("list", lambda u: [f"1 {u}", f"2 {u}"]),
]

QUANTITY_KEYS = [  # (base, key, unit)
    ("plate", "mesh.side", "mm"),
    ("plate", "mesh.element_size", "mm"),
    ("impact", "mesh.spacing", "mm"),
    ("plate", "run.end_time", "us"),
    ("plate", "run.history_interval", "us"),
    ("plate", "sections.fabric.bending_modulus", "GPa"),
    ("plate", "sections.fabric.transverse_shear_modulus", "GPa"),
    ("plate", "sections.fabric.areal_mass", "kg/m^2"),
    ("plate", "sections.fabric.thickness", "mm"),
    ("impact", "impactor.radius", "mm"),
    ("impact", "impactor.length", "mm"),
    ("impact", "impactor.mass", "g"),
    ("impact", "impactor.velocity", "m/s"),
    ("plate", "initial_velocity.0.radius", "mm"),
    ("metal", "sections.sheet.thickness", "mm"),
]


def build() -> Corpus:
    """Every item of the corpus and the files it needs."""
    c = Corpus()
    kevlar = (EXAMPLES / "materials" / "kevlar_thesis.toml").read_text()
    alu = (EXAMPLES / "materials" / "aluminium.toml").read_text()
    c.file("kevlar.toml", kevlar)
    c.file("aluminium.toml", alu)
    c.file("plate.toml", PLATE)
    c.file("impact.toml", IMPACT)
    c.file("metal.toml", METAL)
    c.file("plate.inp", plate_inp())
    c.file("inp_case.toml", INP_CASE)
    c.file("study.toml", STUDY)
    c.file("data.csv", CSV)
    bases = {"plate": PLATE, "impact": IMPACT, "metal": METAL}

    # controls: sane inputs run
    c.run_case("ok_plate", "plate.toml", "ok")
    c.run_case("ok_impact", "impact.toml", "ok")
    c.run_case("ok_metal", "metal.toml", "ok")
    c.run_case("ok_inp", "inp_case.toml", "ok")
    c.run_case("ok_bom", c.file("ok_bom.toml", b"\xef\xbb\xbf" + dumps(PLATE).encode()), "ok",
               "a UTF-8 byte-order mark is accepted")
    c.add("ok_csv", ["calibrate", "compression", "data.csv", "--out", "out/ok_csv", "--json"],
          "ok", "csv")

    # encodings and file kinds, for each input file kind
    text = dumps(PLATE)
    enc = {
        "utf16": text.encode("utf-16"),
        "utf16le_nobom": text.encode("utf-16-le"),
        "latin1_comment": ("# Kevlar\xae fabric, 5 \xb5s\n" + text).encode("latin-1"),
        "binary": bytes(range(256)) * 4,
        "empty": b"",
        "nul": text.encode() + b"\x00\x00",
        "not_toml": b"[case\nname = \n",
    }
    for label, data in enc.items():
        c.run_case(f"case_{label}", c.file(f"case_{label}.toml", data), note=label)
    mtext = kevlar
    menc = {
        "utf16": mtext.encode("utf-16"),
        "latin1_comment": "# \xb5m and \xb0C\n".encode("latin-1") + mtext.encode(),
        "binary": bytes(range(256)) * 4,
        "empty": b"",
    }
    for label, data in menc.items():
        mname = c.file(f"mat_{label}.toml", data)
        c.run_case(f"material_{label}", _set(PLATE, "materials.kevlar", mname), kind="material",
                   note=label)
        c.add(f"element_material_{label}", ["element-test", "uniaxial", "--material", mname,
                                            "--out", f"out/el_{label}"], "error", "material")
    stext = dumps(STUDY)
    senc = {
        "utf16": stext.encode("utf-16"),
        "latin1_comment": ("# d\xe9formation\n" + stext).encode("latin-1"),
        "binary": bytes(range(256)) * 4,
        "empty": b"",
    }
    for label, data in senc.items():
        sname = c.file(f"study_{label}.toml", data)
        c.add(f"study_{label}", ["sweep", sname, "--out", f"out/s_{label}", "--json"], "error",
              "study")
    ienc = {
        "utf16": plate_inp().encode("utf-16"),
        "latin1_comment": ("** mesh by J\xfcrgen\n" + plate_inp()).encode("latin-1"),
        "binary": bytes(range(256)) * 4,
        "empty": b"",
    }
    for label, data in ienc.items():
        iname = c.file(f"inp_{label}.inp", data)
        c.run_case(f"inp_{label}", _set(INP_CASE, "mesh.file", iname), kind="mesh", note=label)
    cenc = {
        "utf16": CSV.encode("utf-16"),
        "latin1_comment": ("d_mm,F_mN\n" + "# \xb5\n" + CSV.split("\n", 1)[1]).encode("latin-1"),
        "binary": bytes(range(256)) * 4,
        "empty": b"",
        "header_only": b"d_mm,F_mN\n",
        "bad_header": ("x,y\n" + CSV.split("\n", 1)[1]).encode(),
        "huge": ("d_mm,F_mN\n" + "\n".join(f"{1e300 * (i + 1)},{1e300 * (i + 2)}"
                                           for i in range(5)) + "\n").encode(),
        "overflow": ("d_mm,F_mN\n" + "\n".join(f"{1e-3 * (i + 1)},{1e308 * (i + 1)}"
                                               for i in range(5)) + "\n").encode(),
        "nan": ("d_mm,F_mN\n0.01,nan\n0.02,3\n0.03,5\n").encode(),
        "inf": ("d_mm,F_mN\n0.01,inf\n0.02,3\n0.03,5\n").encode(),
        "negative": ("d_mm,F_mN\n-0.01,1\n-0.02,3\n-0.03,5\n").encode(),
        "one_row": ("d_mm,F_mN\n0.01,1\n").encode(),
        "text_cell": ("d_mm,F_mN\n0.01,one\n0.02,3\n").encode(),
        "ragged": ("d_mm,F_mN\n0.01,1,7\n0.02\n").encode(),
        "wrong_unit": ("d_kg,F_mN\n0.01,1\n0.02,3\n").encode(),
        "tiny": ("d_mm,F_mN\n" + "\n".join(f"{1e-300 * (i + 1)},{1e-300 * (i + 1)}"
                                           for i in range(5)) + "\n").encode(),
    }
    for label, data in cenc.items():
        cname = c.file(f"csv_{label}.csv", data)
        c.add(f"csv_{label}", ["calibrate", "compression", cname, "--out", f"out/csv_{label}",
                                "--json"], "error", "csv")
    c.add("csv_missing", ["calibrate", "compression", "nope.csv", "--json"], "error", "csv")
    c.add("csv_directory", ["calibrate", "compression", "out", "--json"], "error", "csv")
    c.add("csv_weighting", ["calibrate", "compression", "data.csv", "--weighting", "cubic",
                            "--out", "out/csvw"], "error", "flag")
    c.add("csv_out_file", ["calibrate", "compression", "data.csv", "--out", "an_existing_file"],
          "error", "flag")
    c.add("csv_out_proc", ["calibrate", "compression", "data.csv", "--out", "/proc/wi_out"],
          "error", "flag")
    c.add("csv_out_under_file", ["calibrate", "compression", "data.csv", "--out",
                                 "an_existing_file/sub"], "error", "flag")

    # quantity keys × bad values
    for base, key, unit in QUANTITY_KEYS:
        for label, make in BAD_VALUES:
            c.run_case(f"{key}={label}@{base}", _set(bases[base], key, make(unit)))

    # absurd magnitudes and physically unusable inputs
    P = PLATE
    absurd = [
        ("side_1e30", _set(P, "mesh.side", "1e30 mm"), "error"),
        ("element_1e-300", _set(P, "mesh.element_size", "1e-300 mm"), "error"),
        ("element_1e-5", _set(P, "mesh.element_size", "1e-5 mm"), "error"),
        ("side_1e6_mm", _set(P, "mesh.side", "1e6 mm"), "error"),
        ("element_bigger_than_half_side", _set(P, "mesh.element_size", "6 mm"), "error"),
        ("element_bigger_than_side", _set(P, "mesh.element_size", "20 mm"), "error"),
        ("element_equals_half_side", _set(P, "mesh.element_size", "5 mm"), "error"),
        ("bending_1e30", _set(P, "sections.fabric.bending_modulus", "1e30 GPa"), "error"),
        ("shear_1e30", _set(P, "sections.fabric.transverse_shear_modulus", "1e30 GPa"), "error"),
        ("areal_mass_1e-30", _set(P, "sections.fabric.areal_mass", "1e-30 kg/m^2"), "error"),
        ("areal_mass_1e30", _set(P, "sections.fabric.areal_mass", "1e30 kg/m^2"), "warn"),
        ("areal_mass_x100", _set(P, "sections.fabric.areal_mass", "47.7 kg/m^2"), "warn"),
        ("thickness_1m", _set(P, "sections.fabric.thickness", "1 m"), "error"),
        ("thickness_1e-30", _set(P, "sections.fabric.thickness", "1e-30 mm"), "error"),
        ("end_time_1e6s", _set(P, "run.end_time", "1e6 s"), "error"),
        ("end_time_1s", _set(P, "run.end_time", "1 s"), "error"),
        ("end_time_1e-30", _set(P, "run.end_time", "1e-30 s"), "warn"),
        ("velocity_1e30", _set(P, "initial_velocity.0.velocity",
                               ["0 m/s", "0 m/s", "-1e30 m/s"]), "error"),
        ("velocity_nan", _set(P, "initial_velocity.0.velocity", ["0 m/s", "nan m/s", "0 m/s"]),
         "error"),
        ("velocity_inf", _set(P, "initial_velocity.0.velocity", ["0 m/s", "0 m/s", "-inf m/s"]),
         "error"),
        ("centre_nan", _set(P, "initial_velocity.0.centre", ["nan mm", "0 mm", "0 mm"]), "error"),
        ("angular_nan", _set(P, "initial_velocity.0.angular_velocity",
                             ["0 rad/s", "0 rad/s", "nan rad/s"]), "error"),
        ("gravity_nan", _set(P, "body_force", {"acceleration": ["0 m/s^2", "0 m/s^2",
                                                                "nan m/s^2"]}), "error"),
        ("gravity_1e30", _set(P, "body_force", {"acceleration": ["0 m/s^2", "0 m/s^2",
                                                                 "-1e30 m/s^2"]}), "error"),
        ("warp_nan", _set(P, "mesh.warp_direction", [float("nan"), 0, 0]), "error"),
        ("warp_zero", _set(P, "mesh.warp_direction", [0, 0, 0]), "error"),
        ("warp_normal", _set(P, "mesh.warp_direction", [0, 0, 1]), "error"),
        ("iv_radius_selects_nothing", _set(_set(P, "initial_velocity.0.radius", "1e-6 mm"),
                                           "initial_velocity.0.centre",
                                           ["0.5 mm", "0.5 mm", "0 mm"]), "error"),
        ("iv_unknown_set", _set(P, "initial_velocity.0.nodes", "no_such_set"), "error"),
        ("boundary_unknown_set", _set(P, "boundary.0.nodes", "no_such_set"), "error"),
        ("clamp_and_velocity", _set(P, "boundary", P["boundary"] + [
            {"nodes": "edge_outer", "type": "velocity", "dof": "uz", "velocity": "10 m/s"}]),
         "error"),
        ("two_velocities", _set(_set(P, "boundary", P["boundary"][1:] + [
            {"nodes": "edge_outer", "type": "velocity", "dof": "uz", "velocity": "10 m/s"},
            {"nodes": "edge_outer", "type": "velocity", "dof": "uz", "velocity": "-5 m/s"}]),
            "initial_velocity", []), "error"),
        ("symmetry_and_velocity", _set(P, "boundary", P["boundary"] + [
            {"nodes": "symmetry_x", "type": "velocity", "dof": "ux", "velocity": "1 m/s"}]),
         "error"),
        ("no_boundary_quarter", _set(P, "boundary", [P["boundary"][0]]), "warn"),
        ("full_plate_quarter_sets", _set(P, "mesh.quarter", False), "error"),
        ("max_steps_10", _set(P, "run.max_steps", 10), "error"),
        ("max_steps_0", _set(P, "run.max_steps", 0), "error"),
        ("max_steps_text", _set(P, "run.max_steps", "many"), "error"),
        ("threads_1000", _set(P, "run.threads", 1000), "warn"),
        ("threads_0", _set(P, "run.threads", 0), "error"),
        ("alpha_2", _set(P, "run.alpha", 2), "error"),
        ("plies_0", _set(P, "mesh.plies", 0), "error"),
        ("plies_1e9", _set(_set(P, "mesh.plies", 1000000000), "mesh.spacing", "0.5 mm"),
         "error"),
        ("plies_2_no_spacing", _set(P, "mesh.plies", 2), "error"),
        ("unknown_key", _set(P, "run.end_tme", "2 us"), "error"),
        ("unknown_table", _set(P, "solver", {"x": 1}), "error"),
        ("no_run", _set(P, "run", None), "error"),
        ("no_materials", _set(P, "materials", {}), "error"),
        ("missing_material_file", _set(P, "materials.kevlar", "nowhere.toml"), "error"),
        ("material_is_directory", _set(P, "materials.kevlar", "out"), "error"),
        ("material_absolute_dev", _set(P, "materials.kevlar", "/dev/null"), "error"),
        ("section_unknown_material", _set(P, "sections.fabric.material", "steel"), "error"),
        ("mesh_unknown_section", _set(P, "mesh.section", "nope"), "error"),
        ("mesh_kind_unknown", _set(P, "mesh.kind", "sphere"), "error"),
        ("points_2", _set(P, "sections.fabric.points", 2), "error"),
        ("hourglass_1", _set(P, "sections.fabric.hourglass", 1), "error"),
        ("membrane_bad", _set(P, "sections.fabric.membrane", "half"), "error"),
        # a frame every step of a 13-step run is fine (a warning beyond 1000 outputs)
        ("history_interval_1e-30", _set(P, "run.history_interval", "1e-30 s"), "ok"),
        ("field_interval_1e-30", _set(P, "run.field_interval", "1e-30 s"), "ok"),
        ("checkpoint_interval_1e-30", _set(P, "run.checkpoint_interval", "1e-30 s"), "ok"),
        ("name_empty", _set(P, "case.name", ""), "error"),
        ("case_name_int", _set(P, "case.name", 3), "error"),
        ("ramp_nan", _set(P, "amplitude", {"ramp_time": "nan us"}), "error"),
        ("erosion_radius_nan", _set(P, "initial_erosion", [{"radius": "nan mm"}]), "error"),
        ("erosion_centre_inf", _set(P, "initial_erosion", [{"radius": "1 mm", "centre":
                                    ["inf mm", "0 mm", "0 mm"]}]), "error"),
        ("erosion_everything", _set(P, "initial_erosion", [{"radius": "1 m"}]), "error"),
        ("erosion_ply_5", _set(P, "initial_erosion", [{"radius": "1 mm", "plies": [5]}]),
         "error"),
        # issue 38 item 6: TOML's types kept; a mesh that would take minutes asks first
        ("plies_text", _set(P, "mesh.plies", "1"), "error"),
        ("quarter_yes", _set(P, "mesh.quarter", "yes"), "error"),
        ("quarter_1", _set(P, "mesh.quarter", 1), "error"),
        ("warp_text", _set(P, "mesh.warp_direction", ["1", "0", "0"]), "error"),
        ("threads_float", _set(P, "run.threads", 1.0), "error"),
        ("mesh_941k", _set(_set(P, "mesh.side", "97 mm"), "mesh.element_size", "0.05 mm"),
         "error"),
    ]
    for label, doc, expect in absurd:
        c.run_case(f"absurd_{label}", doc, expect)

    # impactor
    I = IMPACT
    impactor = [
        ("behind_plies", _set(I, "impactor.position", ["0 mm", "0 mm", "-5 mm"]), "error"),
        ("inside_plies", _set(I, "impactor.position", ["0 mm", "0 mm", "-0.1 mm"]), "error"),
        ("a_metre_away", _set(I, "impactor.position", ["0 mm", "0 mm", "1 m"]), "warn"),
        ("away_but_arrives", _set(_set(I, "impactor.position", ["0 mm", "0 mm", "30 mm"]),
                                  "run.end_time", "300 us"), "ok"),
        ("moving_away", _set(I, "impactor.direction", [0, 0, 1]), "error"),
        ("sideways", _set(I, "impactor.direction", [1, 0, 0]), "error"),
        ("off_the_plate", _set(I, "impactor.position", ["50 mm", "50 mm", "0.85 mm"]), "error"),
        ("mass_1e-20g", _set(I, "impactor.mass", "1e-20 g"), "error"),
        ("mass_1e-9g", _set(I, "impactor.mass", "1e-9 g"), "error"),
        ("density_1e-30", _set(_set(I, "impactor.mass", None), "impactor.density",
                               "1e-30 kg/m^3"), "error"),
        ("velocity_1e30", _set(I, "impactor.velocity", "1e30 m/s"), "error"),
        ("velocity_1e-30", _set(I, "impactor.velocity", "1e-30 m/s"), "warn"),
        ("position_nan", _set(I, "impactor.position", ["0 mm", "nan mm", "0.5 mm"]), "error"),
        ("position_inf", _set(I, "impactor.position", ["0 mm", "0 mm", "inf mm"]), "error"),
        ("direction_nan", _set(I, "impactor.direction", [0, float("nan"), -1]), "error"),
        ("direction_zero", _set(I, "impactor.direction", [0, 0, 0]), "error"),
        ("radius_1e30", _set(I, "impactor.radius", "1e30 mm"), "error"),
        ("radius_1e-30", _set(I, "impactor.radius", "1e-30 mm"), "error"),
        ("cylinder_no_length", _set(I, "impactor.length", None), "error"),
        ("shape_cube", _set(I, "impactor.shape", "cube"), "error"),
        ("nose_length_huge", _set(_set(I, "impactor.nose", "conical"), "impactor.nose_length",
                                  "1 m"), "error"),
        ("fillet_huge", _set(I, "impactor.fillet", "10 mm"), "error"),
        ("friction_nan", _set(I, "impactor.friction", "nan"), "error"),
        ("contact_stiffness_0", _set(I, "impactor.contact_stiffness", 0), "error"),
        ("plies_overlap", _set(I, "mesh.spacing", "0.1 mm"), "error"),
        ("plies_overlap_tiny", _set(I, "mesh.spacing", "1e-9 mm"), "error"),
        ("contact_penalty_nan", _set(I, "contact", {"penalty_scale": "nan"}), "error"),
        ("contact_surfaces_bad", _set(I, "contact", {"surfaces": "all"}), "error"),
    ]
    for label, doc, expect in impactor:
        c.run_case(f"impactor_{label}", doc, expect)

    # material geometry and values (through the case's material table `set`)
    def mset(values: dict) -> dict:
        return _set(PLATE, "materials.kevlar", {"file": "kevlar.toml", "set": values})

    mat = [
        ("crimp_10", {"warp": {"crimp": 10}}),
        ("crimp_negative", {"warp": {"crimp": -0.1}}),
        ("crimp_nan", {"fill": {"crimp": float("nan")}}),
        ("thickness_0", {"warp": {"thickness": "0 mm"}}),
        ("thickness_1m", {"warp": {"thickness": "1 m"}}),
        ("width_1m", {"warp": {"width": "1 m"}}),
        ("h0_1m", {"warp": {"h0": "1 m"}}),
        ("h0_negative", {"warp": {"h0": "-1 mm"}}),
        ("area_1e30", {"warp": {"area": "1e30 mm^2"}}),
        ("modulus_1e30", {"warp": {"modulus": "1e30 GPa"}}),
        ("modulus_nan", {"warp": {"modulus": "nan GPa"}}),
        ("thread_count_1e-30", {"fill": {"thread_count": "1e-30 1/in"}}),
        ("thread_count_1e30", {"fill": {"thread_count": "1e30 1/in"}}),
        ("compaction_a_1m", {"compaction": {"a": "1 m"}}),
        ("compaction_a_above_height", {"compaction": {"a": "0.3 mm"}}),
        ("crimp_0", {"warp": {"crimp": 0}}),
        ("h0_0", {"fill": {"h0": "0 mm"}}),
        ("compaction_b_1e300", {"compaction": {"b": "1e300 N"}}),
        ("shear_cmax_2", {"shear": {"c_max": 2}}),
        ("shear_g1_gt_g2", {"shear": {"g1": "100 GPa"}}),
        ("fibre_density_1e-30", {"fibre_density": "1e-30 g/cm^3"}),
        ("fibre_density_nan", {"fibre_density": "nan g/cm^3"}),
        ("unknown_key", {"warp": {"colour": "red"}}),
        ("unknown_table", {"weft": {"crimp": 0.1}}),
    ]
    for label, values in mat:
        c.run_case(f"material_{label}", mset(values), kind="material")
        mdoc_path = c.file(f"mfile_{label}.toml",
                           _material_with(kevlar, values))
        c.add(f"element_{label}", ["element-test", "uniaxial", "--material", mdoc_path,
                                   "--out", f"out/el_{label}", "--steps", "20"], "error",
              "material")

    def aset(values: dict) -> dict:
        return _set(METAL, "materials.al", {"file": "aluminium.toml", "set": values})

    metal = [
        ("density_1e-30", {"density": "1e-30 kg/m^3"}),
        ("density_1e30", {"density": "1e30 kg/m^3"}),
        ("modulus_1e30", {"modulus": "1e30 GPa"}),
        ("poisson_0.5", {"poisson": 0.5}),
        ("poisson_nan", {"poisson": float("nan")}),
        ("hardening_empty", {"plasticity": {"hardening": []}}),
        ("hardening_decreasing", {"plasticity": {"hardening": [["0", "200 MPa"],
                                                               ["0.1", "100 MPa"]]}}),
        ("hardening_strain_unsorted", {"plasticity": {"hardening": [["0.1", "77 MPa"],
                                                                    ["0", "213 MPa"]]}}),
        ("yield_above_modulus", {"plasticity": {"hardening": [["0", "1e6 GPa"]]}}),
        ("fracture_negative", {"plasticity": {"fracture_strain": -1}}),
        ("kind_unknown", {"kind": "rubber"}),
    ]
    for label, values in metal:
        c.run_case(f"metal_{label}", aset(values), kind="material")
    c.run_case("metal_thickness_1m", _set(METAL, "sections.sheet.thickness", "1 m"))
    c.run_case("metal_thickness_1e-30", _set(METAL, "sections.sheet.thickness", "1e-30 m"))
    c.run_case("metal_no_thickness", _set(METAL, "sections.sheet.thickness", None))

    # Abaqus meshes
    inps = {
        "dup_node": plate_inp(dup_node=True),
        "dup_elem": plate_inp(dup_elem=True),
        "nan_coord": plate_inp(nan=True),
        "missing_node": plate_inp(missing_node=True),
        "solid_elements": plate_inp(etype="C3D8R"),
        "degenerate": plate_inp(degenerate=True),
        "include": "*INCLUDE, INPUT=other.inp\n" + plate_inp(),
        "no_elements": plate_inp().split("*ELEMENT")[0],
        "huge_coords": plate_inp(h=1e30),
        "tiny_coords": plate_inp(h=1e-300),
        "text_coord": plate_inp().replace("2, 0.001", "2, abc"),
        "two_node_blocks": plate_inp() + "*NODE\n100, 0, 0, 0\n",
    }
    for label, text in inps.items():
        name = c.file(f"mesh_{label}.inp", text)
        c.run_case(f"inp_{label}", _set(INP_CASE, "mesh.file", name), kind="mesh")
    c.run_case("inp_missing_file", _set(INP_CASE, "mesh.file", "nowhere.inp"), kind="mesh")
    c.run_case("inp_is_directory", _set(INP_CASE, "mesh.file", "out"), kind="mesh")
    c.run_case("inp_unknown_elset", _set(INP_CASE, "mesh.sections", {"nope": "fabric"}),
               kind="mesh")
    c.run_case("inp_unknown_nset", _set(INP_CASE, "boundary.0.nodes", "nope"), kind="mesh")
    msh = c.file("plate.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n")
    c.run_case("msh_file", _set(INP_CASE, "mesh.file", msh), kind="mesh")
    c.run_case("msh_binary", _set(INP_CASE, "mesh.file", c.file("bin.msh", bytes(range(256)))),
               kind="mesh")
    gmsh = _set(INP_CASE, "mesh.kind", "gmsh")
    for label, data in [("garbage", bytes(range(256)) * 3), ("empty", b""),
                        ("utf16", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n".encode("utf-16")),
                        ("an_inp", plate_inp().encode()),
                        ("truncated", b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n")]:
        name = c.file(f"gmsh_{label}.msh", data)
        c.run_case(f"gmsh_{label}", _set(gmsh, "mesh.file", name), kind="mesh")
    c.run_case("inp_element_1e30", _set(_set(INP_CASE, "mesh.file",
                                             c.file("mesh_big.inp", plate_inp(h=1e27))),
                                        "run.end_time", "2 us"), kind="mesh")

    # a containment case (the example, by absolute path) with one value made absurd
    hybrid = str(EXAMPLES / "containment" / "hybrid_4.toml")
    for label, value in [("element_1e30", "mesh.element_size=1e30 mm"),
                         ("element_1e-300", "mesh.element_size=1e-300 mm"),
                         ("end_time_1e6", "run.end_time=1e6 s"),
                         ("layers_0", "mesh.casing.layers=0")]:
        c.add(f"containment_{label}", ["run", hybrid, "--out", f"out/cont_{label}", "--set",
                                       value], "error", "case", timeout=120)
    # the example's graded ring made empty or inside out, a stop rule with no time
    for label, values in [("fine_sector_0", ["mesh.casing.fine_sector=0 deg"]),
                          ("coarse_below_fine", ["mesh.casing.coarse_element_size=1 mm"]),
                          ("fine_wider_than_sector", ["mesh.casing.sector=120 deg"]),
                          ("stop_when_decided_negative", ["run.stop_when_decided=-1 us"])]:
        args = ["run", hybrid, "--out", f"out/cont_{label}"]
        for v in values:
            args += ["--set", v]
        c.add(f"containment_{label}", args, "error", "case", timeout=120)

    # studies
    S = STUDY
    studies = [
        ("empty_list", _set(S, "parameters", {"mesh.side": []})),
        ("not_a_list", _set(S, "parameters", {"mesh.side": "10 mm"})),
        ("no_parameters", _set(S, "parameters", {})),
        ("unknown_key", _set(S, "parameters", {"mesh.sidee": ["10 mm"]})),
        ("bad_value", _set(S, "parameters", {"mesh.side": ["ten mm"]})),
        ("absurd_value", _set(S, "parameters", {"mesh.side": ["1e30 mm"]})),
        ("unknown_metric", _set(S, "study.metrics", ["max_displacment_m"])),
        ("missing_case", _set(S, "study.case", "nowhere.toml")),
        ("case_latin1", _set(S, "study.case", "case_latin1_comment.toml")),
        ("case_utf16", _set(S, "study.case", "case_utf16.toml")),
        ("combine_bad", _set(S, "study.combine", "cross")),
        ("zip_unequal", _set(_set(S, "study.combine", "zip"), "parameters",
                             {"mesh.side": ["10 mm", "12 mm"], "run.end_time": ["1 us"]})),
        ("no_study_table", _set(S, "study", None)),
        ("unknown_study_key", _set(S, "study.workers", 4)),
        ("end_time_1e6", _set(S, "parameters", {"run.end_time": ["1e6 s"]})),
        ("bending_1e30", _set(S, "parameters",
                              {"sections.fabric.bending_modulus": ["1e30 GPa"]})),
        ("index_out_of_range", _set(S, "parameters", {"initial_velocity.5.radius": ["1 mm"]})),
    ]
    for label, doc in studies:
        name = c.file(f"study_{label}.toml", doc)
        c.add(f"study_{label}", ["sweep", name, "--out", f"out/study_{label}", "--json",
                                 "--workers", "1"], "error", "study", timeout=120)
    # the same value twice: issue 12 item 5 asks that the variant run once (with a word)
    name = c.file("study_duplicate_values.toml",
                  _set(S, "parameters", {"mesh.side": ["10 mm", "10 mm"]}))
    c.add("study_duplicate_values", ["sweep", name, "--out", "out/study_duplicate_values",
                                     "--json", "--workers", "1"], "warn", "study", timeout=120)
    c.add("sweep_missing", ["sweep", "nowhere.toml"], "error", "study")
    c.add("sweep_out_file", ["sweep", "study.toml", "--out", "an_existing_file"], "error", "flag")
    c.add("sweep_out_proc", ["sweep", "study.toml", "--out", "/proc/wi_sweep"], "error", "flag")
    c.add("sweep_scheduler_garbage", ["sweep", "study.toml", "--out", "out/sched1",
                                      "--scheduler", "not a scheduler"], "error", "flag",
          timeout=120)
    c.add("sweep_scheduler_unreachable", ["sweep", "study.toml", "--out", "out/sched2",
                                          "--scheduler", "tcp://127.0.0.1:9"], "error", "flag",
          timeout=120)
    c.add("sweep_scheduler_badport", ["sweep", "study.toml", "--out", "out/sched3",
                                      "--scheduler", "tcp://127.0.0.1:99999"], "error", "flag",
          timeout=120)
    c.add("sweep_workers_0", ["sweep", "study.toml", "--workers", "0"], "error", "flag")
    c.add("sweep_bad_set", ["sweep", "study.toml", "--out", "out/sw_set", "--set", "nothing"],
          "error", "flag")
    c.add("sweep_set_unknown", ["sweep", "study.toml", "--out", "out/sw_set2", "--set",
                                "run.endtime=2 us"], "error", "flag")

    # run flags
    flags = [
        ("no_out", ["run", "plate.toml"]),
        ("out_existing_file", ["run", "plate.toml", "--out", "an_existing_file", "--set", SHORT]),
        ("out_under_file", ["run", "plate.toml", "--out", "an_existing_file/x", "--set", SHORT]),
        ("out_proc", ["run", "plate.toml", "--out", "/proc/wi_run", "--set", SHORT]),
        ("out_sys", ["run", "plate.toml", "--out", "/sys/wi_run", "--set", SHORT]),
        ("threads_0", ["run", "plate.toml", "--out", "out/t0", "--threads", "0"]),
        ("threads_text", ["run", "plate.toml", "--out", "out/tt", "--threads", "two"]),
        ("set_no_equals", ["run", "plate.toml", "--out", "out/s1", "--set", "run.end_time"]),
        ("set_unknown", ["run", "plate.toml", "--out", "out/s2", "--set", "run.endtime=2 us"]),
        ("set_bad_value", ["run", "plate.toml", "--out", "out/s3", "--set", "run.end_time=soon"]),
        ("set_index", ["run", "plate.toml", "--out", "out/s4", "--set", "boundary.9.type=x"]),
        ("set_not_table", ["run", "plate.toml", "--out", "out/s5", "--set",
                           "run.end_time.x=1"]),
        ("set_end_time_1e6", ["run", "plate.toml", "--out", "out/s6", "--set",
                              "run.end_time=1e6 s"]),
        ("restart_nothing", ["run", "plate.toml", "--out", "out/rs", "--restart", "--set",
                             SHORT]),
        ("case_missing", ["run", "nowhere.toml", "--out", "out/cm"]),
        ("case_directory", ["run", "out", "--out", "out/cd"]),
        ("case_dev_null", ["run", "/dev/null", "--out", "out/dn"]),
        ("unknown_command", ["fly", "plate.toml"]),
        ("unknown_option", ["run", "plate.toml", "--out", "out/uo", "--fast"]),
    ]
    for label, argv in flags:
        c.add(f"run_{label}", argv, "error", "flag")
    c.add("run_threads_1000", ["run", "plate.toml", "--out", "out/t1000", "--threads", "1000",
                               "--set", SHORT, "--json"], "warn", "flag")

    # element-test flags
    el = [
        ("out_file", ["--out", "an_existing_file"]),
        ("out_proc", ["--out", "/proc/wi_el"]),
        ("out_under_file", ["--out", "an_existing_file/x"]),
        ("displacement_text", ["--out", "out/e1", "--displacement", "far"]),
        ("displacement_nan", ["--out", "out/e2", "--displacement", "nan mm"]),
        ("displacement_1e30", ["--out", "out/e3", "--displacement", "1e30 mm"]),
        ("angle_metres", ["--out", "out/e4", "--angle", "5 m"]),
        ("strain_nan", ["--out", "out/e5", "--strain", "nan"]),
        ("strain_inf", ["--out", "out/e6", "--strain", "inf"]),
        ("strain_negative", ["--out", "out/e7", "--strain", "-1"]),
        ("strain_rate_negative", ["--out", "out/e8", "--strain-rate", "-1 1/s"]),
        ("thickness_negative", ["--out", "out/e9", "--thickness", "-1 mm"]),
        ("steps_0", ["--out", "out/e10", "--steps", "0"]),
        ("steps_1e12", ["--out", "out/e11", "--steps", "1000000000000"]),
        ("material_missing", ["--out", "out/e12", "--material", "nowhere.toml"]),
        ("softening_negative", ["--out", "out/e13", "--softening-strain", "-1"]),
        ("no_out", []),
    ]
    for label, extra in el:
        argv = ["element-test", "uniaxial"]
        if "--material" not in extra:
            argv += ["--material", "kevlar.toml"]
        c.add(f"element_{label}", argv + extra, "error", "flag")
    c.add("element_test_unknown", ["element-test", "twist", "--material", "kevlar.toml",
                                   "--out", "out/e14"], "error", "flag")
    for label, extra in [("out_file", ["--out", "an_existing_file"]),
                         ("strain_nan", ["--out", "out/m1", "--strain", "nan"]),
                         ("thickness_1e30", ["--out", "out/m2", "--thickness", "1e30 m"]),
                         ("strain_rate_1e300", ["--out", "out/m3", "--strain-rate", "1e300 1/s"])]:
        c.add(f"element_metal_{label}", ["element-test", "uniaxial", "--material",
                                         "aluminium.toml", *extra], "error", "flag")

    # design, validate, ballistics, calibrate crimp, bench
    c.add("design_out_file", ["design", "plies", "impact.toml", "--out", "an_existing_file"],
          "error", "flag")
    c.add("design_out_proc", ["design", "plies", "impact.toml", "--out", "/proc/wi_design"],
          "error", "flag")
    c.add("design_no_impactor", ["design", "plies", "plate.toml", "--out", "out/d1"], "error",
          "flag")
    c.add("design_case_utf16", ["design", "plies", "case_utf16.toml", "--out", "out/d2"],
          "error", "flag")
    c.add("design_start_0", ["design", "plies", "impact.toml", "--start", "0"], "error", "flag")
    c.add("design_end_time_1e6", ["design", "plies", "impact.toml", "--out", "out/d3", "--set",
                                  "run.end_time=1e6 s"], "error", "flag", timeout=120)
    c.add("validate_work_file", ["validate", "--work", "an_existing_file", "--study", "x"],
          "error", "flag")
    c.add("validate_work_proc", ["validate", "--work", "/proc/wi_val", "--study", "nope"],
          "error", "flag")
    c.add("validate_report_under_file", ["validate", "--work", "out/val", "--report",
                                         "an_existing_file/x.md", "--study", "nope"],
          "error", "flag")
    c.add("validate_unknown_study", ["validate", "--work", "out/val2", "--study", "nope"],
          "error", "flag")
    for label, data in [("utf16", "id,status\n".encode("utf-16")),
                        ("binary", bytes(range(256))),
                        ("latin1", "id,status\n\xe9,done\n".encode("latin-1")),
                        ("empty", b"")]:
        name = c.file(f"results_{label}.csv", data)
        c.add(f"ballistics_{label}", ["ballistics", "v50", name], "error", "csv")
    c.add("ballistics_missing", ["ballistics", "v50", "nowhere.csv"], "error", "csv")
    for label, extra in [("text", ["--thread-count", "many"]),
                         ("negative", ["--crimp", "-1"]),
                         ("crimp_10", ["--crimp", "10"]),
                         ("nan", ["--crimp", "nan"])]:
        c.add(f"crimp_{label}", ["calibrate", "crimp", *extra], "error", "flag")
    for label, extra in [("sizes_text", ["--sizes", "many"]),
                         ("sizes_0", ["--sizes", "0"]),
                         ("sizes_1e30", ["--sizes", "1e30"]),
                         ("kinds_bad", ["--kinds", "rubber"]),
                         ("threads_0", ["--threads", "0"]),
                         ("steps_0", ["--steps", "0"])]:
        c.add(f"bench_{label}", ["bench", *extra], "error", "flag")
    return c


def _material_with(text: str, values: dict) -> str:
    """The kevlar material file with ``values`` merged into its ``[material]`` table."""
    import tomllib

    doc = tomllib.loads(text)

    def merge(into, new):
        for k, v in new.items():
            if isinstance(v, dict) and isinstance(into.get(k), dict):
                merge(into[k], v)
            else:
                into[k] = v

    merge(doc["material"], values)
    return dumps(doc)


def write_corpus(root: Path) -> list[Item]:
    """Write every file of the corpus under ``root``; returns the items (run with cwd=root)."""
    c = build()
    c.write(root)
    return c.items


if __name__ == "__main__":
    import sys

    items = write_corpus(Path(sys.argv[1] if len(sys.argv) > 1 else "out/corpus"))
    print(f"{len(items)} items")
