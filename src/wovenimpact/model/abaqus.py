"""Read shell and solid meshes from Abaqus input files (``.inp``) through meshio.

Only the mesh is read: ``*NODE``, ``*ELEMENT`` (shell quads and triangles, 8-node
bricks), ``*NSET`` and ``*ELSET`` (including ``GENERATE``). meshio's reader maps every
4-node quad type it knows (S4, S4R, CPS4, …) to "quad" and every 3-node triangle
type (S3, S3R, CPS3, …) to "triangle"; both are accepted, a triangle is stored as a
quad with its last node repeated. The 8-node bricks (C3D8, C3D8R, C3D8I, …: meshio's
"hexahedron", whose corner order is Abaqus's) are the solids, ``Mesh.hexes``, numbered
apart from the shells, their element sets in ``Mesh.hex_sets``. Line and vertex
elements (beams, trusses) are skipped with a warning; any other element type is an
:class:`InputError`.

meshio reads a flat file only; the constructs it would misread silently are
refused with a message instead (checked by :func:`_scan_keywords`): ``*PART``,
``*ASSEMBLY`` and ``*INSTANCE`` (an instance's translation and rotation would be
lost), several ``*NODE`` blocks, ``*INCLUDE``, a set defined twice, an ``*ELSET``
that lists other sets by name, and an ``*ELSET`` placed above an ``*ELEMENT`` block.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.model.mesh import Mesh
from wovenimpact.spec.fields import read_text

SHELL_TYPES = ("quad", "triangle")
SOLID_TYPES = ("hexahedron",)
SKIPPED_TYPES = ("line", "line3", "vertex")


def read_inp(path: str | Path) -> Mesh:
    """Nodes, shell elements and sets of an Abaqus input file, 0-based.

    Elements are numbered in the order they appear in the file (block by block);
    ``Mesh.ply`` is 0 for all of them. Node sets keep their meshio (file) names.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} not found")
    scan = _scan_keywords(path)
    raw = _meshio_read(path)
    if len(raw.cells) != len(scan.element_elsets):
        raise InputError(
            f"{path}: meshio read {len(raw.cells)} element blocks, the file has "
            f"{len(scan.element_elsets)} *ELEMENT keywords"
        )
    offsets = _block_offsets(path, raw.cells)
    quads = np.concatenate(
        [_as_quads(b.data) for b, off in zip(raw.cells, offsets) if off is not None]
        or [np.zeros((0, 4), dtype=np.int64)]
    )
    hex_offsets = _block_offsets(path, raw.cells, SOLID_TYPES)
    hexes = np.concatenate(
        [np.asarray(b.data, dtype=np.int64) for b, off in zip(raw.cells, hex_offsets)
         if off is not None] or [np.zeros((0, 8), dtype=np.int64)]
    )
    if not len(quads) and not len(hexes):
        raise InputError(f"{path}: no shell elements (S4, S4R, S3, S3R) or 8-node bricks "
                         "(C3D8R, C3D8) found")
    nodes = _xyz(path, raw.points)
    bad = np.flatnonzero(~np.all(np.isfinite(nodes), axis=1))
    if bad.size:
        raise InputError(f"{path}: node {bad[0] + 1} (in file order) has a non-finite "
                         f"coordinate {nodes[bad[0]].tolist()} (valid: finite numbers)")
    elem_sets = _elem_sets(raw, scan, offsets)
    hex_sets = _elem_sets(raw, scan, hex_offsets)
    if len(hexes):  # a set of solids only is not a (empty) set of shells
        elem_sets = {k: v for k, v in elem_sets.items() if v.size or not hex_sets.get(
            k, np.zeros(0)).size}
        hex_sets = {k: v for k, v in hex_sets.items() if v.size or k not in elem_sets}
    else:
        hex_sets = {}
    node_sets = {name: np.unique(np.asarray(idx, dtype=np.int64))
                 for name, idx in raw.point_sets.items()}
    return Mesh(nodes=nodes, quads=quads, ply=np.zeros(len(quads), dtype=np.int64),
                node_sets=node_sets, elem_sets=elem_sets, hexes=hexes, hex_sets=hex_sets)


def _meshio_read(path: Path) -> meshio.Mesh:
    """meshio's Abaqus reader, its errors turned into InputError naming the file.

    ``meshio.read(path, file_format="abaqus")`` dispatches to this same reader but
    prints and calls ``sys.exit`` when it raises ReadError; we call it directly.
    """
    try:
        return meshio.abaqus.read(str(path))
    except meshio.ReadError as exc:
        msg = str(exc)
        if msg.startswith("Element type not available"):
            msg += (" (meshio's name; shell types read: S4, S4R, S3, S3R and the other "
                    "4-node quads / 3-node triangles meshio knows, in upper case)")
        raise InputError(f"{path}: {msg}") from None
    except (KeyError, IndexError, ValueError, TypeError, RuntimeError) as exc:
        raise InputError(
            f"{path}: cannot read the mesh ({type(exc).__name__}: {exc}); check that every "
            "node and element a set or element refers to is defined above it"
        ) from None


def _block_offsets(path: Path, cells, types=SHELL_TYPES) -> list[int | None]:
    """Global index of each block's first element among the blocks of ``types`` (the
    shells, or the solids); None for the other blocks."""
    offsets: list[int | None] = []
    n = 0
    for block in cells:
        if block.type in types:
            offsets.append(n)
            n += len(block.data)
        elif block.type in SHELL_TYPES + SOLID_TYPES:
            offsets.append(None)
        elif types is not SHELL_TYPES:
            offsets.append(None)  # (told of by the shells' pass)
        elif block.type in SKIPPED_TYPES:
            warnings.warn(f"{path}: skipping {len(block.data)} {block.type!r} elements "
                          "(only shell quads and triangles are read)", InputWarning,
                          stacklevel=3)
            offsets.append(None)
        else:
            raise InputError(
                f"{path}: element type {block.type!r} (meshio's name) is not a shell or an "
                "8-node brick; valid: "
                "4-node quads (S4, S4R), 3-node triangles (S3, S3R) and 8-node bricks "
                "(C3D8R, C3D8); line and vertex elements are skipped"
            )
    return offsets


def _as_quads(data: np.ndarray) -> np.ndarray:
    """(m, 4) node indices; a triangle's last node repeated."""
    data = np.asarray(data, dtype=np.int64)
    return data if data.shape[1] == 4 else np.column_stack([data, data[:, 2]])


def _xyz(path: Path, points: np.ndarray) -> np.ndarray:
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise InputError(f"{path}: nodes must have 2 or 3 coordinates, got shape {pts.shape}")
    return pts if pts.shape[1] == 3 else np.column_stack([pts, np.zeros(len(pts))])


def _elem_sets(raw: meshio.Mesh, scan: _Keywords, offsets) -> dict[str, np.ndarray]:
    """Element sets as global indices (meshio keeps them per block, local)."""
    sets: dict[str, list[np.ndarray]] = {}
    for name, per_block in raw.cell_sets.items():
        if name in scan.element_declared:
            continue  # meshio may put these on the wrong block; rebuilt below
        for block, local in enumerate(per_block):
            if offsets[block] is not None:
                sets.setdefault(name, []).append(offsets[block] + np.asarray(local, np.int64))
        sets.setdefault(name, [])
    for block, name in enumerate(scan.element_elsets):
        if name is not None and offsets[block] is not None:
            size = len(raw.cells[block].data)
            sets.setdefault(name, []).append(offsets[block] + np.arange(size, dtype=np.int64))
    return {name: np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)
            for name, parts in sets.items()}


@dataclass
class _Keywords:
    """What the keyword lines of an input file say about its structure."""

    element_elsets: list[str | None] = field(default_factory=list)  # ELSET= per *ELEMENT
    element_declared: set[str] = field(default_factory=set)
    last_element_line: int = 0
    elset_lines: dict[str, int] = field(default_factory=dict)  # *ELSET name → line
    nset_lines: dict[str, int] = field(default_factory=dict)  # *NSET name → line


def _scan_keywords(path: Path) -> _Keywords:
    """Check the keyword structure of ``path`` for what meshio would misread."""
    scan = _Keywords()
    n_node_blocks = 0
    pending_elset: str | None = None  # an *ELSET whose first data line comes next
    block = ""  # the keyword whose data lines follow
    ids: dict[str, dict[int, int]] = {"NODE": {}, "ELEMENT": {}}  # id → line, per kind
    continued = False
    for lineno, line in enumerate(read_text(path, "mesh file").splitlines(), 1):
        text = line.strip()
        if not text or text.startswith("**"):
            continue
        if not text.startswith("*"):
            if pending_elset is not None and not text.split(",")[0].strip().isnumeric():
                raise InputError(f"{path}:{lineno}: *ELSET {pending_elset!r} lists other "
                                 "sets by name; list element numbers instead")
            pending_elset = None
            if block in ids and not continued:
                _check_id(ids[block], path, lineno, block, text)
            continued = text.endswith(",")  # an element's nodes go on on the next line
            continue
        pending_elset = None
        continued = False
        keyword, params = _keyword_line(text)
        block = keyword
        if keyword == "NODE":
            n_node_blocks += 1
            if n_node_blocks > 1:
                raise InputError(f"{path}:{lineno}: a second *NODE block (parts or "
                                 "instances?); write the file without parts and assemblies")
        elif keyword in ("PART", "ASSEMBLY", "INSTANCE"):
            raise InputError(f"{path}:{lineno}: *{keyword} is not supported (parts and "
                             "instances would be read without their placement); write the "
                             "file flat (Abaqus/CAE: Model > Edit Attributes > Do not use "
                             "parts and assemblies in input files)")
        elif keyword == "INCLUDE":
            raise InputError(f"{path}:{lineno}: *INCLUDE is not supported; inline the file")
        elif keyword == "ELEMENT":
            scan.element_elsets.append(params.get("ELSET"))
            scan.last_element_line = lineno
            if params.get("ELSET") is not None:
                scan.element_declared.add(params["ELSET"])
        elif keyword == "NSET":
            _define(scan.nset_lines, path, lineno, "node set", params.get("NSET", ""))
        elif keyword == "ELSET":
            pending_elset = params.get("ELSET", "")
            _define(scan.elset_lines, path, lineno, "element set", pending_elset)
    _check_elset_order(path, scan)
    return scan


def _check_id(seen: dict[int, int], path: Path, lineno: int, kind: str, text: str) -> None:
    """The first field of a *NODE / *ELEMENT data line: a number not given before."""
    head = text.split(",")[0].strip()
    try:
        number = int(head)
    except ValueError:
        raise InputError(f"{path}:{lineno}: {head!r} is not a {kind.lower()} number (valid: "
                         "a positive integer id, then the data)") from None
    if number in seen:
        raise InputError(f"{path}:{lineno}: {kind.lower()} {number} is defined again (first "
                         f"on line {seen[number]}); every {kind.lower()} id must be unique")
    seen[number] = lineno


def _define(lines: dict[str, int], path: Path, lineno: int, kind: str, name: str) -> None:
    if name in lines:
        raise InputError(
            f"{path}:{lineno}: {kind} {name!r} is defined again (first on line "
            f"{lines[name]}); meshio keeps only the last definition: merge them"
        )
    lines[name] = lineno


def _check_elset_order(path: Path, scan: _Keywords) -> None:
    """meshio resolves an *ELSET against the elements read so far only."""
    for name, lineno in scan.elset_lines.items():
        if name in scan.element_declared:
            raise InputError(f"{path}:{lineno}: element set {name!r} is given both on "
                             "*ELEMENT, ELSET= and in *ELSET; use one of the two")
        if lineno < scan.last_element_line:
            raise InputError(
                f"{path}:{lineno}: *ELSET {name!r} stands above the *ELEMENT block on line "
                f"{scan.last_element_line}; move the sets below all elements"
            )


def _keyword_line(text: str) -> tuple[str, dict[str, str]]:
    """'*Elset, elset=top, generate' → ('ELSET', {'ELSET': 'top', 'generate': ''})."""
    words = [w.strip() for w in text.lstrip("*").split(",")]
    params: dict[str, str] = {}
    for w in words[1:]:
        key, _, value = w.partition("=")
        params[key.strip().upper() if value else key.strip().lower()] = value.strip()
    return words[0].upper(), params
