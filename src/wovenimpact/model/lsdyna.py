"""Read shell meshes from LS-DYNA keyword decks (``.k``, ``.key``, ``.dyn``); write one.

A small strict reader of the keywords that make a shell mesh — the keyword readers of the
package registry misread or silently dropped cards of the formats below (docs/inputs.md,
"LS-DYNA keyword decks"):

- ``*NODE``: nodes (``TC``/``RC`` constraints are not read: a warning names them);
- ``*ELEMENT_SHELL`` and ``*ELEMENT_SHELL_THICKNESS``: 4-node shells (a triangle repeats
  N3 in N4) and their own thickness;
- ``*PART``: each element's part, and the part's section id;
- ``*SECTION_SHELL`` (``_TITLE``): the thickness T1 (T2–T4 blank or equal to it);
- ``*SET_NODE`` / ``*SET_SHELL`` (``_LIST``, ``_LIST_GENERATE``, ``_TITLE``): sets;
- ``*INCLUDE`` (relative to the including file), ``*KEYWORD`` (``LONG=Y``, ``I10=Y``),
  ``*END``, ``*TITLE``, ``*COMMENT``.

Cards are read in the deck's formats: fixed columns (8/16 for nodes and elements, 10
elsewhere), free format (a card with a comma; a value no longer than its fixed field),
the I10 format (``*NODE %``, ``I10=Y``: fields narrower than 10 widened to 10) and the
long format (``*NODE +``, ``LONG=Y``: every field 20 wide; ``-`` returns a keyword to the
standard format). A field that is not a number of its kind, text beyond a card's last
column, a node or element id given twice, an element on a node the deck lacks, a part
or section id the deck lacks, a set listing an id the deck lacks, a ``&`` parameter and
every variant that would change the mesh if it were skipped (``*NODE_TRANSFORM``,
``*PART_MOVE``, ``*INCLUDE_TRANSFORM``, ``*ELEMENT_SHELL_BETA``, solids, 8-node shells,
layered sections ...) are an :class:`InputError` naming the file, the line, the keyword,
the value and what would be valid. Other keywords (materials, contacts, controls,
boundaries) are skipped with one warning that names them: the case file says those.

The mesh: nodes and elements in deck order (0-based), ``Mesh.ply`` 0. Element sets
``PART_<PID>`` (each part) and ``SET_SHELL_<SID>``; node sets ``SET_NODE_<SID>`` and, for
each element set, the nodes of its elements under the same name (a part can be clamped).
:func:`section_thicknesses` gives the case's sections the deck's thickness;
:func:`write_deck` writes a compiled model as a deck this reader reads back.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model.mesh import Mesh
from wovenimpact.spec.fields import read_text

INT = re.compile(r"[+-]?\d+\Z")
# Fortran reals as decks write them: 1.5, .5, 5., 1.5e-3, 1.5D-3, and 1.5-3 (= 1.5e-3)
REAL = re.compile(r"([+-]?(?:\d+\.?\d*|\.\d+))(?:[eEdD]([+-]?\d+)|([+-]\d+))?\Z")
STANDARD, I10, LONG = "standard", "I10 (%)", "long (+)"
# keywords read for their structure only, never warned of
QUIET = {"KEYWORD", "TITLE", "END", "COMMENT"}
# skipping these would change the mesh: refused
REFUSED = {
    "NODE_": "nodes defined or moved by another keyword are not read; write them in *NODE",
    "PART_": "a part is read from *PART only (no inertia, contact, composite or move "
             "options); write a *PART with its section",
    "INCLUDE_": "*INCLUDE reads a file as it is (no path, transform or stamped-part "
                "options); inline the file or give it by *INCLUDE",
    "ELEMENT_SOLID": "solid elements are not read: the model is shells",
    "ELEMENT_TSHELL": "thick shells are 8-node solids: not read; mesh the part with "
                      "*ELEMENT_SHELL",
    "ELEMENT_SHELL_": "only *ELEMENT_SHELL and *ELEMENT_SHELL_THICKNESS are read (material "
                      "angles, offsets, extra nodes and composite layers are not); the case's "
                      "mesh.warp_direction sets the warp",
    "SECTION_SHELL_": "only *SECTION_SHELL and *SECTION_SHELL_TITLE are read",
    "SET_NODE_": "node sets are read from *SET_NODE(_LIST)(_GENERATE)(_TITLE) only; list "
                 "the nodes",
    "SET_SHELL_": "shell sets are read from *SET_SHELL(_LIST)(_GENERATE)(_TITLE) only; "
                  "list the elements",
}
SET_FORMS = re.compile(r"SET_(NODE|SHELL)(_LIST)?(_GENERATE)?(_TITLE)?\Z")
TITLE_WIDTH = 80


@dataclass
class Deck:
    """What a keyword deck says about its shell mesh.

    Attributes:
        mesh: nodes, elements and sets (0-based, deck order; the deck's length unit).
        thickness: (n_elems,) each element's shell thickness in the deck's length unit:
            its ``*ELEMENT_SHELL_THICKNESS`` card, else its part's ``*SECTION_SHELL`` T1.
        element_ids, part_ids: (n_elems,) the deck's element id and part id (PID).
        node_ids: (n_nodes,) the deck's node ids.
        path: the deck's file.
        titles: set name → the deck's title of it (a part's heading, a set's _TITLE).
    """

    mesh: Mesh
    thickness: np.ndarray
    element_ids: np.ndarray
    part_ids: np.ndarray
    node_ids: np.ndarray
    path: Path
    titles: dict[str, str] = field(default_factory=dict)


def read_k(path: str | Path) -> Mesh:
    """The mesh of an LS-DYNA keyword deck (:func:`read_deck`)."""
    return read_deck(path).mesh


# --------------------------------------------------------------------------- reading


@dataclass
class _Card:
    """A data line: its file, line number and text (tabs refused, trailing blanks cut)."""

    file: Path
    line: int
    text: str

    def where(self) -> str:
        return f"{self.file}:{self.line}"


@dataclass
class _Block:
    """A keyword and its data lines (comments removed)."""

    name: str  # upper case, without '*' and the format suffix
    fmt: str
    file: Path
    line: int
    cards: list[_Card]

    def where(self) -> str:
        return f"{self.file}:{self.line}: *{self.name}"


def _keyword(text: str, card: _Card, default: str) -> tuple[str, str, list[str]]:
    """'*NODE %' → ('NODE', I10, []); the words after the name come back as a list."""
    words = text[1:].split()
    if not words:
        raise InputError(f"{card.where()}: a '*' line without a keyword name")
    name = words[0].upper()
    rest = words[1:]
    suffix = None
    if name[-1] in "+-%":
        suffix, name = name[-1], name[:-1]
    elif rest and rest[0] in ("+", "-", "%"):
        suffix, rest = rest[0], rest[1:]
    fmt = {"+": LONG, "%": I10, "-": STANDARD, None: default}[suffix]
    return name, fmt, rest


def _blocks(path: Path, default: str, stack: tuple[Path, ...] = ()) -> list[_Block]:
    """The keyword blocks of ``path`` with its ``*INCLUDE`` files read in place."""
    real = path.resolve()
    if real in stack:
        raise InputError(f"{path}: *INCLUDE loops back to a file that includes it "
                         f"({' → '.join(str(p) for p in stack + (real,))})")
    text = read_text(path, "mesh file")
    blocks: list[_Block] = []
    current: _Block | None = None
    fmt = default
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.rstrip()
        if line.startswith("$"):
            continue
        card = _Card(path, lineno, line)
        if line.startswith("*"):
            name, kfmt, rest = _keyword(line, card, fmt)
            if current is not None:
                blocks.extend(_finish(current, stack + (real,)))
            if name == "END":
                current = None
                break
            if name == "KEYWORD":
                fmt = _deck_format(rest, card, fmt)
                kfmt = fmt
            current = _Block(name, kfmt, path, lineno, [])
            if rest and name not in ("KEYWORD", "TITLE", "COMMENT") and _is_read(name):
                raise InputError(f"{card.where()}: *{name}: unexpected text after the keyword "
                                 f"{' '.join(rest)!r} (valid: nothing, or a format suffix "
                                 "'+' (long), '%' (I10) or '-' (standard))")
            continue
        if current is None:
            if line.strip():
                raise InputError(f"{card.where()}: data before the first keyword "
                                 f"({line.strip()[:40]!r}); a deck starts with *KEYWORD")
            continue
        if "\t" in line and current.name not in ("TITLE", "COMMENT") and _is_read(current.name):
            raise InputError(f"{card.where()}: *{current.name}: a tab character; fixed "
                             "columns are counted in spaces (valid: spaces, or commas "
                             "between the values)")
        current.cards.append(card)
    if current is not None:
        blocks.extend(_finish(current, stack + (real,)))
    return blocks


def _deck_format(words: list[str], card: _Card, fmt: str) -> str:
    """The deck's format from *KEYWORD's options (LONG=Y / S / K, I10=Y / N)."""
    for w in words:
        key, _, value = w.upper().partition("=")
        if key == "LONG" and value == "Y":
            fmt = LONG
        elif key == "LONG" and value in ("S", "K", "N"):
            fmt = STANDARD if fmt == LONG else fmt
        elif key == "I10" and value == "Y":
            fmt = I10
        elif key == "I10" and value == "N":
            fmt = STANDARD if fmt == I10 else fmt
        elif key in ("LONG", "I10"):
            raise InputError(f"{card.where()}: *KEYWORD {w}: not a format (valid: LONG=Y, "
                             "LONG=S, I10=Y)")
    return fmt


def _finish(block: _Block, stack: tuple[Path, ...]) -> list[_Block]:
    """A finished block, or the blocks of the file an *INCLUDE names."""
    if block.name != "INCLUDE":
        return [block]
    names: list[str] = []
    pending = ""
    for card in block.cards:
        text = card.text.strip()
        if not text and not pending:
            continue
        if text.endswith(" +"):  # a long file name continues on the next line
            pending += text[:-2].rstrip()
            continue
        names.append(pending + text)
        pending = ""
    if pending:
        names.append(pending)
    if len(names) != 1:
        raise InputError(f"{block.where()}: {len(names)} file names (valid: one file per "
                         "*INCLUDE)")
    target = (block.file.parent / names[0]).expanduser()
    if not target.is_file():
        raise InputError(f"{block.where()}: file {names[0]!r} not found (looked for "
                         f"{target})")
    return _blocks(target, block.fmt, stack)


def _is_read(name: str) -> bool:
    return name in ("NODE", "ELEMENT_SHELL", "ELEMENT_SHELL_THICKNESS", "PART",
                    "SECTION_SHELL", "SECTION_SHELL_TITLE", "INCLUDE") or bool(
        SET_FORMS.match(name))


def _widths(widths: list[int], fmt: str) -> list[int]:
    if fmt == LONG:
        return [20] * len(widths)
    if fmt == I10:
        return [max(w, 10) for w in widths]
    return list(widths)


def _fields(card: _Card, block: _Block, widths: list[int], names: list[str]) -> list[str]:
    """The card's fields as stripped text ('' where blank): split at commas (free format)
    or at the fixed columns of ``widths`` in the block's format."""
    widths = _widths(widths, block.fmt)
    text = card.text
    if "," in text:
        parts = [p.strip() for p in text.split(",")]
        while len(parts) > len(widths) and parts[-1] == "":
            parts.pop()
        if len(parts) > len(widths):
            raise InputError(f"{card.where()}: *{block.name}: {len(parts)} values in a card "
                             f"of {len(widths)} fields ({', '.join(names)}) (got {text!r})")
        for p, w, n in zip(parts, widths, names):
            if len(p) > w:
                raise InputError(
                    f"{card.where()}: *{block.name}: {n} {p!r} is {len(p)} characters, more "
                    f"than its field's {w} (in free format a value may be no longer than its "
                    f"fixed field, as LS-DYNA reads it; valid: fewer digits, or the long "
                    f"format '*{block.name} +' with 20-character fields)")
        return parts + [""] * (len(widths) - len(parts))
    out, start = [], 0
    for w in widths:
        out.append(text[start:start + w].strip())
        start += w
    if text[start:].strip():
        raise InputError(
            f"{card.where()}: *{block.name}: text beyond column {start} "
            f"({text[start:].strip()[:30]!r}); the {block.fmt} format's fields "
            f"({', '.join(names)}) are {'/'.join(str(w) for w in widths)} characters wide "
            f"(valid: values in their columns, commas between them, or the format "
            f"the deck is written in: '*{block.name} +' long, '*{block.name} %' I10)")
    return out


def _int(value: str, card: _Card, block: _Block, name: str, *, required: bool = True,
         positive: bool = True) -> int:
    if value.startswith("&"):
        raise _parameter(value, card, block, name)
    if not value:
        if required:
            raise InputError(f"{card.where()}: *{block.name}: {name} is blank (valid: "
                             "an integer id > 0)")
        return 0
    if not INT.match(value):
        raise InputError(f"{card.where()}: *{block.name}: {name} is not an integer (got "
                         f"{value!r}; valid: an integer id such as 12, in its columns — "
                         f"a value that spills into the next field reads as another)")
    number = int(value)
    if positive and number <= 0 and (required or number < 0):
        raise InputError(f"{card.where()}: *{block.name}: {name} = {number} (valid: an "
                         "integer id > 0)")
    return number


def _real(value: str, card: _Card, block: _Block, name: str) -> float:
    if value.startswith("&"):
        raise _parameter(value, card, block, name)
    if not value:
        return 0.0
    m = REAL.match(value)
    if not m:
        raise InputError(f"{card.where()}: *{block.name}: {name} is not a number (got "
                         f"{value!r}; valid: a number such as 0.25, 2.5e-1 or 2.5-1, in its "
                         "columns)")
    exponent = m.group(2) or m.group(3) or "0"
    number = float(f"{m.group(1)}e{exponent}")
    if not math.isfinite(number):
        raise InputError(f"{card.where()}: *{block.name}: {name} = {value!r} is not finite")
    return number


def _parameter(value: str, card: _Card, block: _Block, name: str) -> InputError:
    return InputError(f"{card.where()}: *{block.name}: {name} is the parameter {value!r}; "
                      "*PARAMETER references are not read (valid: write the value)")


def _label(value: str, card: _Card, block: _Block, name: str) -> str:
    """A section or material id: an integer (as its number) or a character label."""
    if value.startswith("&"):
        raise _parameter(value, card, block, name)
    if not value:
        raise InputError(f"{card.where()}: *{block.name}: {name} is blank (valid: the id "
                         "of a *SECTION_SHELL)")
    return str(int(value)) if INT.match(value) else value


@dataclass
class _Section:
    label: str
    thickness: tuple[float, float, float, float]
    where: str


def _data_cards(block: _Block) -> list[_Card]:
    return [c for c in block.cards if c.text.strip()]


def _groups(cards: list[_Card], per: int) -> list[_Card]:
    """The cards of a keyword whose entries take ``per`` cards each: a blank card is a
    card of blank fields, blank lines past the last whole entry are dropped."""
    cards = list(cards)
    while len(cards) % per and cards and not cards[-1].text.strip():
        cards.pop()
    return cards


def _node_block(block: _Block, ids: dict, coords: list, warned: Counter) -> None:
    names = ["NID", "X", "Y", "Z", "TC", "RC"]
    for card in _data_cards(block):
        f = _fields(card, block, [8, 16, 16, 16, 8, 8], names)
        nid = _int(f[0], card, block, "NID")
        xyz = [_real(f[k], card, block, names[k]) for k in (1, 2, 3)]
        for k in (4, 5):
            if f[k] and _real(f[k], card, block, names[k]) != 0.0:
                warned[f"*NODE {names[k]} (nodal constraints)"] += 1
        if nid in ids:
            raise InputError(f"{card.where()}: *NODE: node {nid} is defined again (first at "
                             f"{ids[nid][1]}); every node id must be unique")
        ids[nid] = (len(coords), card.where())
        coords.append(xyz)


def _shell_block(block: _Block, elems: list, seen: dict) -> None:
    names = ["EID", "PID"] + [f"N{k}" for k in range(1, 9)]
    thick = block.name == "ELEMENT_SHELL_THICKNESS"
    cards = _groups(block.cards, 2) if thick else _data_cards(block)
    if thick:  # pairs of cards; a blank thickness card stands (its section's thickness)
        if len(cards) % 2:
            raise InputError(f"{block.where()}: {len(cards)} cards; each element takes two "
                             "(the element, then its thicknesses THIC1–THIC4)")
    step = 2 if thick else 1
    for i in range(0, len(cards), step):
        card = cards[i]
        f = _fields(card, block, [8] * 10, names)
        eid = _int(f[0], card, block, "EID")
        pid = _int(f[1], card, block, "PID")
        nodes = [_int(f[k], card, block, names[k], required=k < 5) for k in range(2, 10)]
        if any(nodes[4:]):
            raise InputError(f"{card.where()}: *{block.name}: element {eid} has mid-side "
                             "nodes N5–N8; 8-node shells are not read (valid: 4-node shells, "
                             "N5–N8 blank)")
        if eid in seen:
            raise InputError(f"{card.where()}: *{block.name}: element {eid} is defined again "
                             f"(first at {seen[eid]}); every element id must be unique")
        seen[eid] = card.where()
        t = (0.0, 0.0, 0.0, 0.0)
        if thick:
            tc = cards[i + 1]
            g = _fields(tc, block, [16] * 5, ["THIC1", "THIC2", "THIC3", "THIC4", "BETA"])
            t = tuple(_real(g[k], tc, block, f"THIC{k + 1}") for k in range(4))
            if g[4] and _real(g[4], tc, block, "BETA") != 0.0:
                raise InputError(f"{tc.where()}: *{block.name}: element {eid} has a material "
                                 f"angle BETA = {g[4]}; angles are not read (the case's "
                                 "mesh.warp_direction sets the warp)")
        elems.append((eid, pid, nodes[:4], t, card.where()))


def _part_block(block: _Block, parts: dict) -> None:
    cards = _groups(block.cards, 2)
    if len(cards) % 2:
        raise InputError(f"{block.where()}: {len(cards)} cards; each part takes two (its "
                         "heading, then PID SECID MID ...)")
    names = ["PID", "SECID", "MID", "EOSID", "HGID", "GRAV", "ADPOPT", "TMID"]
    for i in range(0, len(cards), 2):
        card = cards[i + 1]
        f = _fields(card, block, [10] * 8, names)
        pid = _int(f[0], card, block, "PID")
        secid = _label(f[1], card, block, "SECID")
        if pid in parts:
            raise InputError(f"{card.where()}: *PART: part {pid} is defined again (first at "
                             f"{parts[pid][2]})")
        parts[pid] = (secid, cards[i].text.strip(), card.where())


def _section_block(block: _Block, sections: dict) -> None:
    title = block.name.endswith("_TITLE")
    per = 3 if title else 2
    cards = _groups(block.cards, per)
    if len(cards) % per:
        raise InputError(f"{block.where()}: {len(cards)} cards; each section takes {per} "
                         f"({'a title, ' if title else ''}SECID ELFORM ... ICOMP, then "
                         "T1–T4 ...)")
    names1 = ["SECID", "ELFORM", "SHRF", "NIP", "PROPT", "QR/IRID", "ICOMP", "SETYP"]
    names2 = ["T1", "T2", "T3", "T4", "NLOC", "MAREA", "IDOF", "EDGSET"]
    for i in range(0, len(cards), per):
        c1, c2 = cards[i + per - 2], cards[i + per - 1]
        f = _fields(c1, block, [10] * 8, names1)
        label = _label(f[0], c1, block, "SECID")
        icomp = _int(f[6], c1, block, "ICOMP", required=False, positive=False)
        if icomp != 0:
            raise InputError(f"{c1.where()}: *{block.name}: section {label} has ICOMP = "
                             f"{icomp}: layered (composite) sections are not read (valid: "
                             "ICOMP = 0; the case's section gives the layup)")
        g = _fields(c2, block, [10] * 8, names2)
        t = tuple(_real(g[k], c2, block, names2[k]) for k in range(4))
        if label in sections:
            raise InputError(f"{c1.where()}: *{block.name}: section {label} is defined again "
                             f"(first at {sections[label].where})")
        sections[label] = _Section(label, t, c2.where())


def _set_block(block: _Block, kind: str, generate: bool, title: bool, sets: dict) -> None:
    cards = [c for c in block.cards]
    if title:
        cards = cards[1:]
    while cards and not cards[0].text.strip():
        cards = cards[1:]
    if not cards:
        raise InputError(f"{block.where()}: no set id card (SID ...)")
    head = cards[0]
    f = _fields(head, block, [10] * 8, ["SID", "DA1", "DA2", "DA3", "DA4", "SOLVER", "ITS",
                                        "(unused)"])
    sid = _int(f[0], head, block, "SID")
    if sid in sets:
        raise InputError(f"{head.where()}: *{block.name}: {kind} set {sid} is defined again "
                         f"(first at {sets[sid][2]})")
    entries: list[tuple[int, int, _Card]] = []  # (first, last, card)
    what = "NID" if kind == "node" else "EID"
    for card in _data_cards(_Block(block.name, block.fmt, block.file, block.line,
                                   cards[1:])):
        g = _fields(card, block, [10] * 8, [f"{what}{k}" for k in range(1, 9)])
        values = [_int(v, card, block, f"{what}{k + 1}", required=False)
                  for k, v in enumerate(g)]
        if generate:
            for k in range(0, 8, 2):
                b, e = values[k], values[k + 1]
                if b == 0 and e == 0:
                    continue
                if b <= 0 or e < b:
                    raise InputError(f"{card.where()}: *{block.name}: range {b}–{e} (valid: "
                                     "pairs of ids B ≤ E, both > 0)")
                entries.append((b, e, card))
        else:
            entries.extend((v, v, card) for v in values if v != 0)
    sets[sid] = (entries, generate, head.where(), block.cards[0].text.strip() if title else "")


def read_deck(path: str | Path) -> Deck:
    """Nodes, shells, parts, section thicknesses and sets of an LS-DYNA keyword deck (see
    the module docstring); an :class:`InputError` names what cannot be read."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} not found")
    node_ids: dict[int, tuple[int, str]] = {}
    coords: list[list[float]] = []
    elems: list = []
    elem_seen: dict[int, str] = {}
    parts: dict[int, tuple[str, str, str]] = {}
    sections: dict[str, _Section] = {}
    node_sets: dict[int, tuple] = {}
    shell_sets: dict[int, tuple] = {}
    skipped: Counter = Counter()
    for block in _blocks(path, STANDARD):
        name = block.name
        if name == "NODE":
            _node_block(block, node_ids, coords, skipped)
        elif name in ("ELEMENT_SHELL", "ELEMENT_SHELL_THICKNESS"):
            _shell_block(block, elems, elem_seen)
        elif name == "PART":
            _part_block(block, parts)
        elif name in ("SECTION_SHELL", "SECTION_SHELL_TITLE"):
            _section_block(block, sections)
        elif (m := SET_FORMS.match(name)) is not None:
            kind = "node" if m.group(1) == "NODE" else "shell"
            _set_block(block, kind, bool(m.group(3)), bool(m.group(4)),
                       node_sets if kind == "node" else shell_sets)
        elif name in QUIET:
            continue
        else:
            for prefix, why in REFUSED.items():
                if name.startswith(prefix):
                    raise InputError(f"{block.where()}: not read: {why}")
            skipped[f"*{name}"] += 1
    if skipped:
        listed = ", ".join(f"{k} ({n})" if n > 1 else k for k, n in sorted(skipped.items()))
        warnings.warn(f"{path}: not read (the case file gives the model's materials, "
                      f"boundaries, contact and controls): {listed}", InputWarning,
                      stacklevel=2)
    return _assemble(path, node_ids, coords, elems, parts, sections, node_sets, shell_sets)


def _assemble(path, node_ids, coords, elems, parts, sections, node_sets, shell_sets) -> Deck:
    if not elems:
        raise InputError(f"{path}: no shell elements (*ELEMENT_SHELL) found")
    index = {nid: i for nid, (i, _) in node_ids.items()}
    quads = np.zeros((len(elems), 4), dtype=np.int64)
    thickness = np.zeros(len(elems))
    eids = np.zeros(len(elems), dtype=np.int64)
    pids = np.zeros(len(elems), dtype=np.int64)
    part_elems: dict[int, list[int]] = {}
    for e, (eid, pid, nodes, t, where) in enumerate(elems):
        if nodes[3] == 0:
            raise InputError(f"{where}: *ELEMENT_SHELL: element {eid} has no N4 (valid: four "
                             "nodes; a triangle repeats N3 in N4)")
        for k, nid in enumerate(nodes):
            if nid not in index:
                raise InputError(f"{where}: *ELEMENT_SHELL: element {eid}'s N{k + 1} is node "
                                 f"{nid}, which no *NODE defines")
            quads[e, k] = index[nid]
        if len(set(nodes)) < 3 or (len(set(nodes)) == 3 and nodes[2] != nodes[3]):
            raise InputError(f"{where}: *ELEMENT_SHELL: element {eid} has nodes {nodes}; "
                             "valid: four different nodes, or a triangle N1 N2 N3 N3")
        if pid not in parts:
            raise InputError(f"{where}: *ELEMENT_SHELL: element {eid} is in part {pid}, which "
                             f"no *PART defines (parts: {sorted(parts) or 'none'})")
        secid = parts[pid][0]
        if secid not in sections:
            raise InputError(f"{parts[pid][2]}: *PART: part {pid} has SECID {secid}, which no "
                             f"*SECTION_SHELL defines (sections: {sorted(sections) or 'none'})")
        thickness[e] = _element_thickness(eid, t, where, sections[secid], pid)
        eids[e], pids[e] = eid, pid
        part_elems.setdefault(pid, []).append(e)
    eindex = {int(eid): e for e, eid in enumerate(eids)}
    elem_sets = {f"PART_{pid}": np.asarray(idx, dtype=np.int64)
                 for pid, idx in part_elems.items()}
    titles = {f"PART_{pid}": p[1] for pid, p in parts.items()}
    titles.update({f"SET_SHELL_{sid}": s[3] for sid, s in shell_sets.items() if s[3]})
    titles.update({f"SET_NODE_{sid}": s[3] for sid, s in node_sets.items() if s[3]})
    for sid, (entries, generate, _, _) in shell_sets.items():
        elem_sets[f"SET_SHELL_{sid}"] = _members(entries, generate, eindex, np.sort(eids),
                                                 "element", sid, "*SET_SHELL")
    nodes = np.asarray(coords, dtype=float).reshape(-1, 3)
    sorted_ids = np.array(sorted(index), dtype=np.int64)
    node_id_of = np.zeros(len(nodes), dtype=np.int64)
    for nid, i in index.items():
        node_id_of[i] = nid
    node_set_arrays = {
        f"SET_NODE_{sid}": _members(entries, generate, index, sorted_ids, "node", sid,
                                    "*SET_NODE")
        for sid, (entries, generate, _, _) in node_sets.items()}
    for name, idx in elem_sets.items():
        node_set_arrays[name] = np.unique(quads[idx])
    used = np.unique(quads)
    if used.size < len(nodes):  # nodes of skipped elements (beams, masses): left out
        renumber = np.full(len(nodes), -1, dtype=np.int64)
        renumber[used] = np.arange(used.size)
        quads = renumber[quads]
        nodes, node_id_of = nodes[used], node_id_of[used]
        node_set_arrays = {k: renumber[v[renumber[v] >= 0]]
                           for k, v in node_set_arrays.items()}
    mesh = Mesh(nodes=nodes, quads=quads, ply=np.zeros(len(quads), dtype=np.int64),
                node_sets={k: np.sort(v) for k, v in node_set_arrays.items()},
                elem_sets={k: np.sort(v) for k, v in elem_sets.items()})
    return Deck(mesh=mesh, thickness=thickness, element_ids=eids, part_ids=pids,
                node_ids=node_id_of, path=path, titles=titles)


def _element_thickness(eid, own, where, section: _Section, pid) -> float:
    """The element's own THIC1–THIC4 when given, else its section's T1–T4; one value
    (blank T2–T4 / THIC2–THIC4 take T1 / THIC1, as LS-DYNA reads them)."""
    source, t = (f"element {eid}'s THIC1–THIC4", own) if any(own) else (
        f"*SECTION_SHELL {section.label} (part {pid})", section.thickness)
    at = where if any(own) else section.where
    if not t[0] > 0.0:
        raise InputError(f"{at}: {source}: T1 = {t[0]:g} (valid: a thickness > 0)")
    values = [t[0]] + [v if v != 0.0 else t[0] for v in t[1:]]
    if max(values) - min(values) > 1e-9 * t[0]:
        raise InputError(f"{at}: {source}: thicknesses {list(t)} differ; a tapered shell is "
                         "not modelled (valid: T2–T4 blank or equal to T1)")
    return float(t[0])


def _members(entries, generate, index, ids_sorted, what, sid, keyword) -> np.ndarray:
    out: list[int] = []
    for b, e, card in entries:
        if generate:
            lo, hi = np.searchsorted(ids_sorted, [b, e + 1])
            found = [index[int(i)] for i in ids_sorted[lo:hi]]
            if not found:
                raise InputError(f"{card.where()}: {keyword}: set {sid}'s range {b}–{e} holds "
                                 f"no {what} of the deck")
            out.extend(found)
        else:
            if b not in index:
                raise InputError(f"{card.where()}: {keyword}: set {sid} lists {what} {b}, "
                                 f"which the deck does not define")
            out.append(index[b])
    return np.unique(np.asarray(out, dtype=np.int64))


# --------------------------------------------------------------------------- sections


def section_thicknesses(deck: Deck, names: list[str], sections: dict, length_unit: float,
                        file: str) -> dict:
    """The case's sections with the deck's thickness: each case section (``names``: the
    section of each element) must find one thickness in the deck's elements it is given
    to; a section without ``thickness`` takes it, one with ``thickness`` must agree with it
    (1e-6). Returns the sections that change (name → Section)."""
    out = {}
    t = deck.thickness * length_unit
    names_arr = np.asarray(names, dtype=object)
    for name in dict.fromkeys(names):
        idx = np.flatnonzero(names_arr == name)
        lo, hi = idx[np.argmin(t[idx])], idx[np.argmax(t[idx])]
        if t[hi] - t[lo] > 1e-9 * t[hi]:
            raise InputError(
                f"mesh.sections: section {name!r} is given to elements of {file} of thickness "
                f"{t[lo]:.6g} m (element {deck.element_ids[lo]}, part "
                f"{deck.part_ids[lo]}) and {t[hi]:.6g} m (element {deck.element_ids[hi]}, "
                f"part {deck.part_ids[hi]}); one section has one thickness (valid: give the "
                "parts of each thickness a section of their own)")
        section = sections[name]
        if section.thickness is None:
            out[name] = dataclasses.replace(section, thickness=float(t[lo]))
        elif abs(section.thickness - t[lo]) > 1e-6 * section.thickness:
            raise InputError(
                f"mesh.sections: sections.{name}.thickness is {section.thickness:.6g} m, the "
                f"deck {file} gives its elements {t[lo]:.6g} m (element "
                f"{deck.element_ids[lo]}, part {deck.part_ids[lo]}: its *SECTION_SHELL T1 "
                f"or its own *ELEMENT_SHELL_THICKNESS); the case does not override the deck "
                f"(valid: remove sections.{name}.thickness to take the deck's, or make the "
                "two agree)")
    return out


# --------------------------------------------------------------------------- writing


def real_text(x: float, width: int) -> str:
    """``x`` in at most ``width`` characters: exactly (it reads back as the same double)
    when one of its decimal forms fits — 0.25, 2.5e-1, or 2.5-1 (a Fortran real, which
    LS-DYNA's fixed columns read) — else the closest form that fits."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError(f"not a finite number: {x!r}")
    if x == 0.0:
        return "0.0"
    exact = next(p for p in range(1, 18) if float(f"{x:.{p - 1}e}") == x)
    for p in range(exact, 0, -1):  # significant digits, the exact count first
        mantissa, _, exp_text = f"{abs(x):.{p - 1}e}".partition("e")
        digits, exp = mantissa.replace(".", "").rstrip("0") or "0", int(exp_text)
        sign = "-" if x < 0 else ""
        lead = f"{digits[0]}.{digits[1:] or '0'}"
        if exp >= 0:
            whole = (digits + "0" * (exp + 1))[:exp + 1]
            fixed = f"{whole}.{digits[exp + 1:] or '0'}"
        else:
            fixed = f"0.{'0' * (-exp - 1)}{digits}"
        forms = [f"{sign}{fixed}", f"{sign}{lead}e{exp}", f"{sign}{lead}{exp:+d}"]
        fits = [f for f in forms if len(f) <= width]
        if fits:
            return min(fits, key=len)
    raise ValueError(f"{x!r} does not fit in {width} characters")


def write_deck(path: str | Path, model, title: str = "") -> Path:
    """Write a compiled model's shell mesh (:class:`~wovenimpact.model.model.Model`) as
    an LS-DYNA keyword deck that :func:`read_deck` reads back to the same mesh: nodes and
    elements numbered 1, 2, ... in the model's order, one part per contact surface and
    section (its ``*SECTION_SHELL`` the section's thickness), every element set a
    ``*SET_SHELL_LIST_TITLE`` and every node set a ``*SET_NODE_LIST_TITLE`` (ids 1, 2, ...
    in name order, the title the set's name). Coordinates are written in the long format
    (``*NODE +``, 20 columns), exact wherever a double fits 20 characters; lengths in
    metres. Returns the path."""
    path = Path(path)
    names = list(model.section_names)
    thick = model.sections[:, SL.C_THICK]
    key = list(zip(np.asarray(model.ply).tolist(), np.asarray(model.elem_section).tolist()))
    part_of = {k: i + 1 for i, k in enumerate(dict.fromkeys(key))}
    lines = ["*KEYWORD", "*TITLE", (title or "wovenimpact mesh")[:TITLE_WIDTH],
             "$ written by wovenimpact (model/lsdyna.py): lengths in metres", "*NODE +"]
    lines += ["".join([f"{i + 1:20d}"] + [f"{real_text(v, 20):>20}" for v in xyz])
              for i, xyz in enumerate(np.asarray(model.x0, dtype=float))]
    lines.append("*ELEMENT_SHELL")
    for e, (quad, k) in enumerate(zip(np.asarray(model.quads), key)):
        lines.append(f"{e + 1:8d}{part_of[k]:8d}" + "".join(f"{n + 1:8d}" for n in quad))
    for (ply, sec), pid in part_of.items():
        lines += ["*PART", f"{names[sec]}, surface {ply}"[:70],
                  f"{pid:10d}{sec + 1:10d}{sec + 1:10d}"]
    for sec, name in enumerate(names):  # long format: the thickness exact as a coordinate
        t = real_text(thick[sec], 20)
        lines += ["*SECTION_SHELL_TITLE +", name[:TITLE_WIDTH],
                  f"{sec + 1:20d}{2:20d}{'0.833333':>20}{2:20d}", f"{t:>20}" * 4]
    for kind, sets in (("SHELL", model.elem_sets), ("NODE", model.node_sets)):
        for sid, (name, idx) in enumerate(sorted(sets.items()), 1):
            lines += [f"*SET_{kind}_LIST_TITLE", str(name)[:TITLE_WIDTH], f"{sid:10d}"]
            ids = np.asarray(idx, dtype=np.int64) + 1
            lines += ["".join(f"{v:10d}" for v in ids[i:i + 8]) for i in range(0, len(ids), 8)]
    lines.append("*END")
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path
