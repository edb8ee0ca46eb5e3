"""Render docs/performance.md from the benchmarks' saved figures (``make bench``,
``make bench-containment``).

The page is sections between ``<!-- section: NAME -->`` and ``<!-- end section: NAME -->``
markers, with text around them that this script leaves as it is. A section is rewritten
when its figures are in ``--dir`` (default ``out/bench``) and kept, with the machine and
date it was measured on, when they are not:

- ``bench``: ``fabric_kernel.json``, ``shell.json`` (with the machine) and ``contact.json`` —
  what ``benchmarks/bench_fabric_kernel.py``, ``bench_shell.py`` and ``bench_contact.py``
  write with ``--save=PATH``, the same numbers they print;
- ``containment``: ``containment.json`` (``benchmarks/bench_containment.py --save=PATH``);
- ``flagship``: ``flagship.json`` (the same script on the flagship case, see the Makefile's
  ``bench-flagship``).

Usage: ``python benchmarks/performance_page.py [--dir=out/bench] [--page=docs/performance.md]``.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SECTION = re.compile(r"<!-- section: (?P<name>[\w-]+) -->\n(?P<body>.*?)<!-- end section: (?P=name) -->",
                     re.S)


def save_json(doc: dict, argv: list[str]) -> None:
    """``--save=PATH`` among a benchmark's ``argv``: write ``doc`` (what its ``--json``
    prints) to PATH as well, for this page (``make bench`` renders docs/performance.md)."""
    for arg in argv:
        if arg.startswith("--save="):
            path = Path(arg.split("=", 1)[1])
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def replace_sections(page: str, sections: dict[str, str]) -> str:
    """``page`` with the body of each section named in ``sections`` replaced; sections not
    named, and the text around the markers, are kept as they are."""
    def body(m: re.Match) -> str:
        new = sections.get(m["name"])
        text = m["body"] if new is None else new.rstrip("\n") + "\n"
        return f"<!-- section: {m['name']} -->\n{text}<!-- end section: {m['name']} -->"

    return SECTION.sub(body, page)


def section_names(page: str) -> list[str]:
    return [m["name"] for m in SECTION.finditer(page)]


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return (["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            + ["| " + " | ".join(r) + " |" for r in rows])


def bench_section(machine: str, fabric_kernel: dict, shell: dict, contact: dict) -> str:
    """The ``make bench`` section: its machine line, how busy the machine was, and one table
    per benchmark."""
    out = ["## `make bench`", "", f"`{machine}`", ""]
    load = shell.get("load_average")
    if load:
        out += [f"Load average (1, 5, 15 min) during the step benchmark: "
                f"{', '.join(f'{x:.2f}' for x in load)}. Above about 1 on a 2-core machine other "
                "work shared the cores: every figure is then slower than the machine's, and two "
                "threads can be slower than one.", ""]
    out += [
           "*The explicit step* (`benchmarks/bench_shell.py`, `wovenimpact bench`): a clamped "
           "square plate pre-stretched 2 % and moving, 20 timed steps; ns per element-cycle of "
           "the whole step, bytes of arrays per element, and the ratio to the elastic plate of "
           "the same size and threads.", ""]
    rows = []
    for c in shell["cases"]:
        ratio = c.get("ratio_to_elastic")
        rows.append([c["name"], f"{c['elements']:,}".replace(",", " "), str(c["threads"]),
                     f"{c['ns_per_element_cycle']:.0f}", f"{c.get('bytes_per_element', 0):.0f}",
                     "" if ratio is None else f"{ratio:.2f}"])
    out += _table(["plate", "elements", "threads", "ns per element-cycle", "B per element",
                   "× elastic"], rows)
    out += ["", "*The crossover kernel alone* (`benchmarks/bench_fabric_kernel.py`): a "
            "material-point update from a converged state to a nearby one, ns per point "
            "(minimum of repeats).", ""]
    rows = [[c["crossover"], f"{c['points']:,}".replace(",", " "), str(c["threads"]),
             f"{c['ns_per_point_update']:.1f}", f"{c['iterations_mean']:.2f}"]
            for c in fabric_kernel["cases"]]
    out += _table(["crossover", "points", "threads", "ns per point update",
                   "height-solve iterations (mean)"], rows)
    out += ["", "*Ply-on-ply contact* (`benchmarks/bench_contact.py`): stacked plies pressed "
            "together and sliding; ns per node and call with a search at every call, with "
            "the candidates reused (most steps), the search alone, and the energy books.", ""]
    rows = [[str(c["plies"]), str(c["threads"]), f"{c['nodes']:,}".replace(",", " "),
             f"{c['ns_per_node']:.0f}", f"{c['reused_ns_per_node']:.0f}",
             f"{c['broad_ns_per_node']:.0f}", f"{c['book_ns_per_node']:.0f}"]
            for c in contact["cases"]]
    out += _table(["plies", "threads", "nodes", "search", "reuse", "search alone", "books"],
                  rows)
    return "\n".join(out) + "\n"


def run_section(title: str, row: dict, target: bool) -> str:
    """A whole-run section (``bench_containment.py``'s figures for a case)."""
    hourglass = row.get("hourglass_fraction")
    exit_speed = row.get("fragment_exit_speed_m_per_s")
    lines = [title, "", f"`{row['machine']}`", "",
             f"`{row['case']}` at {row['element_size']} elements, to {row['end_time']} at most, "
             f"{row['threads']} thread(s): {row['elements']:,} elements, {row['steps']:,} steps, "
             f"**{row['wall_time_s']:.1f} s** of run, {row['ns_per_element_cycle']:.0f} ns per "
             "element-cycle".replace(",", " ")]
    if target:
        lines[-1] += f" ({row['ratio_to_target']:.2f}× the {row['target_s']:.0f} s target)"
    lines[-1] += "."
    facts = [f"outcome {row['outcome']}"]
    if exit_speed is not None:
        facts.append(f"exit speed {exit_speed:.1f} m/s from "
                     f"{row['fragment_initial_speed_m_per_s']:.1f}")
    facts.append(f"energy error {row['energy_error_fraction']:.1e}")
    if hourglass is not None:
        facts.append(f"hourglass {hourglass:.1%} of the internal work")
    facts.append(f"added mass {row.get('added_mass_fraction') or 0.0:.2%}")
    lines += ["", "; ".join(facts) + "."]
    return "\n".join(lines) + "\n"


def load(directory: Path, name: str) -> dict | None:
    path = directory / f"{name}.json"
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else None


def sections_from(directory: Path) -> dict[str, str]:
    """The sections whose figures are in ``directory``."""
    out = {}
    parts = {n: load(directory, n) for n in ("fabric_kernel", "shell", "contact")}
    if all(parts.values()):
        from wovenimpact.benchmark import machine_line

        out["bench"] = bench_section(machine_line(parts["shell"]["machine"]),
                                     parts["fabric_kernel"], parts["shell"], parts["contact"])
    containment = load(directory, "containment")
    if containment:
        out["containment"] = run_section(
            "## The containment benchmark (`make bench-containment`)", containment, True)
    flagship = load(directory, "flagship")
    if flagship:
        out["flagship"] = run_section("## The flagship (`make run`)", flagship, False)
    return out


def main(argv: list[str]) -> None:
    opts = dict(a.lstrip("-").split("=", 1) for a in argv if "=" in a)
    directory = Path(opts.get("dir", ROOT / "out" / "bench"))
    page_path = Path(opts.get("page", ROOT / "docs" / "performance.md"))
    sections = sections_from(directory)
    page = page_path.read_text(encoding="utf-8")
    page_path.write_text(replace_sections(page, sections), encoding="utf-8")
    kept = [n for n in section_names(page) if n not in sections]
    shown = page_path.relative_to(ROOT) if page_path.is_relative_to(ROOT) else page_path
    print(f"{shown}: rewrote {', '.join(sorted(sections)) or 'nothing'}"
          + (f"; kept {', '.join(kept)} (no figures for them)" if kept else ""))


if __name__ == "__main__":
    main(sys.argv[1:])
