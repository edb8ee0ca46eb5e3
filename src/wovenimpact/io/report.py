"""``report.html``: one self-contained page per run, per study and per validation.

A run's page sits beside its ``summary.json`` and reads like an engineering report: the
answer and how far to trust it come first, on one screen, before any detail.

1. **Answer**: boxes for the run's kind, each green (``pass``), red (``fail``), blue
   (``info``: a figure with no pass/fail rule) or grey (``na``: the summary has no value).
   A containment run (a blade fragment and a casing): the outcome (green when contained),
   the fragment's exit speed (green at 0 m/s; its speed at release beside it), the energy
   absorbed by the casing (``casing_absorbed_energy_J``, J, with its share of the
   fragment's ½ m v² at release) and the largest bulge of the outermost layer
   (``max_bulge_m``, in mm). A plate impact: the outcome (green when stopped), the
   residual velocity (green at 0 m/s; the rebound speed of a stopped impactor and the
   impact velocity beside it), the energy absorbed (J) and the largest deflection (mm).
   A run without an impactor: its largest displacement (mm).
2. **How far to trust this**: the mesh verdict (:mod:`wovenimpact.results.mesh_verdict`: each
   failing material's element lengths against the range its failure law is calibrated
   for; red for a law that is not regularised, on elements away from its reference
   size), the energy error against the run's ``energy_tolerance`` (default
   :data:`ENERGY_ERROR_LIMIT`, 1 %), the hourglass share ``hourglass_fraction`` against
   :data:`HOURGLASS_LIMIT` (10 %), the mass added by mass scaling against
   :data:`ADDED_MASS_LIMIT` (2 %, none without mass scaling) and whether the outcome
   settled (``outcome_settled``: a plate's outcome decided, a fragment's exit speed steady
   over the run's last 500 µs); then the element size(s) (``element_size_m``,
   ``blade_element_size_m``) and the ``--set`` overrides or study parameters the run was
   made with. Thresholds are written in the unit of their value.
3. **Summary**: summary.json grouped — answer, energies, casing and fragment (or plies),
   run and checks, and any key this version does not describe under "other" — in
   engineering units (mm, m/s, J, kg/m², ms, µs, %), each row with its meaning and its
   summary.json key (:mod:`wovenimpact.io.summary_keys`); ``summary_version`` and
   ``provenance`` are in the provenance section instead;
4. the deformed structure at a few instants (``pictures/``, drawn from the run's VTU
   frames by :mod:`wovenimpact.io.pictures`), each ``<figure data-frame=K
   data-vtu=FILES data-drawn=N data-alive=N>`` with its caption, then every PNG of
   ``plots/``, inlined as base64;
5. the case as run: the TOML text as written, then the ``--set`` overrides that were
   applied on top of it (a study variant: the validated case as JSON, in SI units, and
   its parameters);
6. provenance: code version, the case digest, the run digest, the model digest and the
   summary's version.

The page needs no network: CSS and images are inline, nothing is fetched. A study's
page (``OUT/report.html`` of a sweep) tabulates the variants with links to each run's
page and inlines the comparison plots; :func:`write_index` links every page under a
directory (``wovenimpact validate``), each with its answer and any failed check. Each
answer and trust box is an element ``<div class="verdict pass|fail|info|na"
data-key=KEY data-status=STATUS>`` (KEY the summary key it reads; ``outcome_settled``
reads several), each row of the grouped summary ``<tr data-key=KEY>`` under
``<h3 id="summary-GROUP">``, and the trust block ``<section id="trust">``, so a test (or
a script) can read the page back.
"""

from __future__ import annotations

import base64
import hashlib
import json
from dataclasses import dataclass
from datetime import datetime, timezone
from html import escape
from pathlib import Path

from wovenimpact.io.atomic import atomic_write_text
from wovenimpact.io.summary_keys import grouped, is_containment_summary

ENERGY_ERROR_LIMIT = 0.01  # largest energy-balance error fraction of a trusted run
HOURGLASS_LIMIT = 0.10  # largest hourglass energy / internal work of a trusted run
ADDED_MASS_LIMIT = 0.02  # largest added mass / model mass (run.max_added_mass_fraction's default)

CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 70em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 2em; }
.verdicts { display: flex; flex-wrap: wrap; gap: 0.8em; }
.verdict { border-radius: 6px; padding: 0.6em 1em; min-width: 13em; color: #fff; }
.verdict .name { font-size: 0.85em; opacity: 0.9; } .verdict .value { font-size: 1.3em; }
.verdict .note { font-size: 0.8em; opacity: 0.9; }
.pass { background: #2e7d32; } .fail { background: #c62828; } .na { background: #757575; }
.info { background: #1565c0; }
#trust .verdict { padding: 0.4em 0.8em; } #trust .verdict .value { font-size: 1.05em; }
#trust h2, #answer { margin-top: 1em; } p.lead { margin: 0 0 0.5em 0; color: #555; }
table.facts { margin-top: 0.8em; } table.facts th { text-align: left; background: #f5f5f5; }
table.summary td.meaning { color: #555; font-size: 0.9em; }
table.summary code { font-size: 0.8em; color: #777; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: 0.2em 0.6em; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.pass { color: #2e7d32; font-weight: bold; background: none; }
td.fail { color: #c62828; font-weight: bold; background: none; }
img { max-width: 100%; display: block; margin: 1em 0; }
.pictures { display: flex; flex-wrap: wrap; gap: 0.5em; }
.pictures figure { margin: 0; width: 34em; max-width: 100%; }
.pictures figcaption { font-size: 0.8em; color: #555; }
pre { background: #f5f5f5; padding: 1em; overflow-x: auto; }
.pass-text { color: #2e7d32; } .fail-text { color: #c62828; }
"""


@dataclass(frozen=True)
class Verdict:
    """One box of a run's page: ``status`` is "pass", "fail", "info" (a figure with no
    rule) or "na" (no value: its key is absent or none); ``threshold`` is "" for an info
    box; ``note`` a line of context under the value."""

    key: str
    name: str
    value: str
    threshold: str
    status: str
    note: str = ""


def _status(ok: bool | None) -> str:
    return "na" if ok is None else ("pass" if ok else "fail")


HELD = ("stopped", "contained")  # the outcomes that mean the structure held


def _info(key: str, name: str, value: float | None, text, note: str = "") -> Verdict:
    return (Verdict(key, name, "n/a", "", "na") if value is None
            else Verdict(key, name, text(value), "", "info", note))


def _share(part: float | None, whole: float | None, of: str) -> str:
    if part is None or not whole:
        return ""
    return f"{100.0 * part / whole:.0f} % of {of} ({whole:.4g} J)"


def has_impactor(summary: dict) -> bool:
    """Whether a plate run's summary is of an impact (an outcome, a residual velocity)."""
    return "outcome" in summary or "residual_velocity_m_per_s" in summary


def answer_boxes(summary: dict) -> list[Verdict]:
    """The answer of a run, by its kind (module docstring, item 1)."""
    outcome = summary.get("outcome")
    if is_containment_summary(summary):
        exit_speed = summary.get("fragment_exit_speed_m_per_s")
        v0, mass = summary.get("fragment_initial_speed_m_per_s"), summary.get("fragment_mass_kg")
        ke0 = 0.5 * mass * v0 * v0 if v0 is not None and mass is not None else None
        undecided = exit_speed is None and outcome == "undecided"
        absorbed = summary.get("casing_absorbed_energy_J")
        bulge = summary.get("max_bulge_m")
        return [
            Verdict("outcome", "outcome", "n/a" if outcome is None else str(outcome),
                    "contained", _status(None if outcome is None else outcome == "contained")),
            Verdict("fragment_exit_speed_m_per_s", "fragment exit speed",
                    "none: undecided" if undecided else "n/a" if exit_speed is None
                    else f"{exit_speed:.1f} m/s", "0 m/s: contained",
                    _status(None if exit_speed is None else exit_speed == 0.0),
                    "" if v0 is None else f"released at {v0:.1f} m/s"),
            _info("casing_absorbed_energy_J", "energy absorbed by the casing", absorbed,
                  lambda e: f"{e:.4g} J",
                  _share(absorbed, ke0, "the fragment's ½ m v² at release")),
            _info("max_bulge_m", "largest bulge", bulge, lambda b: f"{b * 1e3:.3g} mm",
                  "outermost layer, outwards"),
        ]
    if not has_impactor(summary):  # a structure loaded otherwise (an initial velocity)
        return [Verdict("outcome", "outcome", "n/a: no impactor", "", "na"),
                _info("max_displacement_m", "largest displacement",
                      summary.get("max_displacement_m"), lambda d: f"{d * 1e3:.3g} mm",
                      "of any node, at the end")]
    residual = summary.get("residual_velocity_m_per_s")
    rebound = summary.get("rebound_velocity_m_per_s")
    v0 = summary.get("initial_velocity_m_per_s")
    residual_text = "n/a" if residual is None else f"{residual:.1f} m/s"
    if residual is not None and rebound:
        residual_text += f", rebound {rebound:.1f} m/s"
    absorbed = summary.get("absorbed_energy_J")
    deflection = summary.get("max_deflection_m")
    return [
        Verdict("outcome", "outcome", "n/a" if outcome is None else str(outcome), "stopped",
                _status(None if outcome is None else outcome == "stopped")),
        Verdict("residual_velocity_m_per_s", "residual velocity", residual_text, "0 m/s",
                _status(None if residual is None else residual == 0.0),
                "" if v0 is None else f"struck at {v0:.1f} m/s"),
        _info("absorbed_energy_J", "energy absorbed", absorbed, lambda e: f"{e:.4g} J",
              _share(absorbed, summary.get("initial_impactor_kinetic_energy_J"),
                     "the impactor's kinetic energy")),
        _info("max_deflection_m", "largest deflection", deflection,
              lambda d: f"{d * 1e3:.3g} mm", "of any ply, at the end"),
    ]


def settled_box(summary: dict) -> Verdict:
    """Whether the answer had settled when the run ended: a plate's outcome decided; a
    containment run's outcome decided and, if escaped, the fragment's exit speed steady
    (``fragment_exit_speed_settled``)."""
    outcome = summary.get("outcome")
    name, key = "outcome settled", "outcome_settled"
    if outcome is None:
        return Verdict(key, name, "n/a" if is_containment_summary(summary) or has_impactor(
            summary) else "n/a: no impactor", "decided", "na")
    if outcome == "undecided":
        what = ("run longer, or model more of the ring if the fragment left a sector"
                if is_containment_summary(summary) else
                "still in contact or pushing intact plies: run longer")
        return Verdict(key, name, "no: undecided at the end", "decided", "fail", what)
    if not is_containment_summary(summary):
        return Verdict(key, name, f"yes: {outcome}", "decided", "pass")
    stopped = summary.get("stopped_when_decided")
    how = ("the run stopped once it had held for run.stop_when_decided" if stopped
           else "at the end time")
    if outcome != "escaped":
        return Verdict(key, name, f"yes: {outcome}", "decided, exit speed steady", "pass", how)
    steady = summary.get("fragment_exit_speed_settled")
    if steady is None:
        return Verdict(key, name, "escaped; exit speed not checked", "decided, exit speed "
                       "steady", "na", "an older summary without fragment_exit_speed_settled")
    return Verdict(key, name, "yes: escaped, exit speed steady" if steady else
                   "no: exit speed still changing", "decided, exit speed steady",
                   _status(bool(steady)),
                   "within 0.5 % over the last 500 µs" if steady else
                   "the fragment still drags torn plies: run longer")


def trust_boxes(summary: dict) -> list[Verdict]:
    """The checks of "How far to trust this" (module docstring, item 2)."""
    error = summary.get("energy_error_fraction")
    limit = summary.get("energy_tolerance", ENERGY_ERROR_LIMIT)  # the run's own, if given
    hourglass = summary.get("hourglass_fraction")
    added = summary.get("added_mass_fraction")
    added_kg = summary.get("added_mass_kg")
    return [
        mesh_box(summary),
        Verdict("energy_error_fraction", "energy error",
                "n/a" if error is None else f"{error * 100:.2g} %", f"≤ {limit * 100:.2g} %",
                _status(None if error is None else error <= limit)),
        Verdict("hourglass_fraction", "hourglass share of internal work",
                "n/a" if hourglass is None else f"{hourglass * 100:.3g} %",
                f"≤ {HOURGLASS_LIMIT * 100:.0f} %",
                _status(None if hourglass is None else hourglass <= HOURGLASS_LIMIT)),
        Verdict("added_mass_fraction", "mass added by mass scaling",
                "none (no mass scaling)" if added is None
                else f"{added * 100:.2g} % of the model's mass",
                f"≤ {ADDED_MASS_LIMIT * 100:.0f} %",
                _status(added is None or added <= ADDED_MASS_LIMIT),
                "" if added_kg is None else f"{added_kg * 1e3:.3g} g"),
        settled_box(summary),
    ]


def verdicts(summary: dict) -> list[Verdict]:
    """Every box of a run's page: :func:`answer_boxes`, then :func:`trust_boxes`."""
    return answer_boxes(summary) + trust_boxes(summary)


MESH_THRESHOLD = "failure calibrated for these elements; the striker's edge resolved"


def mesh_box(summary: dict) -> Verdict:
    """The mesh verdict (:mod:`wovenimpact.results.mesh_verdict`): green when every failing
    material's elements lie at its reference size or within its calibrated range."""
    from wovenimpact.results.mesh_verdict import SUMMARY_KEY, verdict_text

    found = summary.get(SUMMARY_KEY)
    if found is None:
        return Verdict(SUMMARY_KEY, "mesh", "n/a", MESH_THRESHOLD, "na")
    text, ok = verdict_text(found)
    return Verdict(SUMMARY_KEY, "mesh", text, MESH_THRESHOLD, _status(ok))


def element_size_text(summary: dict) -> str:
    """The element size(s) of a run in mm: "casing 10 mm, blade 5 mm", "casing 7 mm
    around × 2 mm along the axis, blade 5 mm" or "2 mm"."""
    size, blade = summary.get("element_size_m"), summary.get("blade_element_size_m")
    if size is None and blade is None:
        return "not in this summary (written before wovenimpact recorded it): see the mesh box"
    mm = (lambda v: "n/a" if v is None else f"{v * 1e3:.3g} mm")
    if "casing_axial_element_size_m" in summary:
        axial = summary["casing_axial_element_size_m"]
        return f"casing {mm(size)} around × {mm(axial)} along the axis, blade {mm(blade)}"
    if "blade_element_size_m" in summary:
        return f"casing {mm(size)}, blade {mm(blade)}"
    return mm(size)


def _value_text(v) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, list):
        return ", ".join(_value_text(x) for x in v)
    if isinstance(v, dict):
        return "; ".join(f"{k}: {_value_text(x)}" for k, x in v.items())
    return "—" if v is None else str(v)


def _page(title: str, body: list[str]) -> str:
    return "\n".join(["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
                      f"<title>{escape(title)}</title>", f"<style>{CSS}</style></head><body>",
                      f"<h1>{escape(title)}</h1>", *body, "</body></html>", ""])


def _verdict_html(v: Verdict) -> str:
    threshold = f" (threshold {escape(v.threshold)})" if v.threshold else ""
    note = f'<div class="note">{escape(v.note)}</div>' if v.note else ""
    return (f'<div class="verdict {v.status}" data-key="{escape(v.key)}" '
            f'data-status="{v.status}"><div class="name">{escape(v.name)}{threshold}</div>'
            f'<div class="value">{escape(v.value)}</div>{note}</div>')


def _summary_html(summary: dict) -> list[str]:
    """The summary grouped (:func:`wovenimpact.io.summary_keys.grouped`): a table per
    group, each row its label (its key on hover and in the last column), value, unit
    and meaning."""
    out = []
    for group, title, rows in grouped(summary):
        out += [f'<h3 id="summary-{group}">{escape(title)}</h3>',
                '<table class="summary"><tr><th>quantity</th><th>value</th><th>unit</th>'
                "<th>meaning</th><th>summary.json key</th></tr>"]
        for r in rows:
            out.append(f'<tr data-key="{escape(r.key)}"><td title="{escape(r.key)}">'
                       f'{escape(r.label)}</td><td class="num">{escape(r.value)}</td>'
                       f"<td>{escape(r.unit)}</td><td class=\"meaning\">{escape(r.meaning)}</td>"
                       f"<td><code>{escape(r.key)}</code></td></tr>")
        out.append("</table>")
    return out


def _overrides_html(overrides, what: str) -> str:
    return (", ".join(f"<code>{escape(o)}</code>" for o in overrides)
            or f"none: the case {what}")


def _kind_line(summary: dict) -> str:
    if is_containment_summary(summary):
        return "Containment run: a released blade fragment against a casing."
    if has_impactor(summary):
        return "Plate impact run: an impactor against a stack of plies."
    return "Run without an impactor: the structure's own motion (no outcome to decide)."


def _table(rows: list[dict], columns: list[str], cell=None) -> list[str]:
    """An HTML table; ``cell(row, column)`` may return (html, css class) for a cell."""
    out = ["<table><tr>" + "".join(f"<th>{escape(c)}</th>" for c in columns) + "</tr>"]
    for r in rows:
        cells = []
        for c in columns:
            html, cls = cell(r, c) if cell else (None, "")
            if html is None:
                v = r.get(c)
                html = escape(_value_text(v))
                cls = cls or ("num" if isinstance(v, (int, float)) else "")
            cells.append(f'<td class="{cls}">{html}</td>' if cls else f"<td>{html}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    return out + ["</table>"]


def _images(folder: Path) -> list[str]:
    """Every PNG of ``folder`` inlined (name as caption), sorted by name."""
    out = []
    for png in sorted(folder.glob("*.png")):
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        out += [f"<h3>{escape(png.name)}</h3>",
                f'<img alt="{escape(png.name)}" src="data:image/png;base64,{data}">']
    return out or ["<p>(no plots)</p>"]


def _pictures_html(out: Path) -> list[str]:
    """The section of the deformed structure's pictures (``OUT/pictures``, listed in its
    pictures.json by :func:`wovenimpact.io.pictures.write_pictures`), each inlined with a
    caption: its time, the frame's VTU files, what is in view and how many elements were
    drawn; nothing when the run has none."""
    index = out / "pictures" / "pictures.json"
    if not index.exists():
        return []
    entries = json.loads(index.read_text(encoding="utf-8"))
    if not entries:
        return []
    body = ['<h2 id="pictures">Deformed structure</h2>',
            "<p>The structure at a few instants (from first contact to the end), drawn from "
            "the run's field frames (<code>fields/</code>): fabric coloured by damage, metal "
            "by plastic strain; eroded elements are not drawn, the rims of their holes are "
            "outlined in magenta.</p>",
            '<div class="pictures">']
    for e in entries:
        png = out / "pictures" / e["file"]
        if not png.exists():
            continue
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        vtu = ", ".join(e.get("vtu", []))
        eroded = int(e["elements_in_view"]) - int(e["alive_in_view"])
        body.append(
            f'<figure data-frame="{int(e["frame"])}" data-vtu="{escape(vtu)}" '
            f'data-drawn="{int(e["drawn"])}" data-alive="{int(e["alive_in_view"])}">'
            f'<img alt="{escape(e["file"])}" src="data:image/png;base64,{data}">'
            f"<figcaption>t = {e['time_s'] * 1e6:.1f} µs ({escape(vtu)}): "
            f"{escape(e.get('caption', ''))}; {int(e['drawn'])} elements drawn of "
            f"{int(e['elements_in_view'])} in view ({eroded} eroded, hidden).</figcaption>"
            "</figure>")
    return body + ["</div>"]


def digest(text: str) -> str:
    """SHA-256 of a text, 16 hex digits (the case digest of a report)."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def write_run_report(out_dir: str | Path, *, spec=None, case_text: str | None = None,
                     case_path: str | Path | None = None, overrides=(),
                     model_digest: str | None = None) -> Path:
    """Write ``OUT/report.html`` for the finished run in ``out_dir`` (its summary.json and
    plots/); returns its path.

    Args:
        out_dir: the run's output directory.
        spec: the validated CaseSpec, shown as JSON when there is no ``case_text``.
        case_text: the case file's TOML text as read; ``case_path`` its path.
        overrides: the ``--set KEY=VALUE`` changes applied to it.
        model_digest: :meth:`Model.digest` of the compiled model.
    """
    from wovenimpact import __version__

    out = Path(out_dir)
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    title = f"{summary.get('case', out.name)}: run report"
    parameters = out / "parameters.json"
    what = "as written"
    if parameters.exists():  # a study's variant: its parameters are its overrides
        overrides = [f"{k}={json.dumps(v)}" for k, v in
                     json.loads(parameters.read_text(encoding="utf-8")).items()]
        what = "as the study wrote it"
    overrides = list(overrides or ())
    body = [f'<p class="lead">{escape(_kind_line(summary))}</p>',
            '<h2 id="verdicts">Answer</h2>', '<div class="verdicts">',
            *(_verdict_html(v) for v in answer_boxes(summary)), "</div>",
            '<section id="trust"><h2>How far to trust this</h2>', '<div class="verdicts">',
            *(_verdict_html(v) for v in trust_boxes(summary)), "</div>",
            '<table class="facts">',
            f'<tr><th>element size</th><td data-key="element_size_m">'
            f"{escape(element_size_text(summary))}</td></tr>",
            f'<tr><th>overrides (--set / study parameters)</th><td data-key="overrides">'
            f"{_overrides_html(overrides, what)}</td></tr>",
            "</table></section>",
            '<h2 id="summary">Summary</h2>',
            "<p>summary.json in engineering units (the file itself is in SI units); every "
            "energy is of the whole problem.</p>",
            *_summary_html(summary),
            *_pictures_html(out),
            '<h2 id="plots">Plots</h2>', *_images(out / "plots"),
            '<h2 id="case">Case as run</h2>']
    if case_text is not None:
        shown = case_text
        body.append(f"<p>{escape(str(case_path or 'case file'))}, as written; the overrides "
                    "below replace its values (the case as run is this text with them "
                    "applied).</p>")
    elif spec is not None:
        shown = spec.model_dump_json(indent=2)
        body.append("<p>The validated case (every quantity in SI units).</p>")
    else:
        shown = ""
        body.append("<p>(the case is not known to this page)</p>")
    if shown:
        body.append(f'<pre class="case">{escape(shown)}</pre>')
    body.append("<p>Overrides (--set / study parameters): "
                + _overrides_html(overrides, what) + "</p>")
    prov = summary.get("provenance") if isinstance(summary.get("provenance"), dict) else {}
    if "case_digest" in prov:  # one digest on the page: the summary's (provenance.py)
        case_row = {"item": "case digest (SHA-256 of the case as resolved, overrides applied)",
                    "value": prov["case_digest"]}
    else:  # a summary without provenance (an element test): the text and overrides
        case_row = {"item": "case digest (SHA-256 of the text and overrides)",
                    "value": digest(shown + "".join(f"\n--set {o}" for o in overrides))
                    if shown else "n/a"}
    body += ['<h2 id="provenance">Provenance</h2>',
             *_table([{"item": "wovenimpact version", "value": __version__}, case_row,
                      *([{"item": "run digest (case, files read and code)",
                          "value": prov["digest"]}] if "digest" in prov else []),
                      {"item": "model digest", "value": model_digest or "n/a"},
                      *([{"item": "summary version (summary.json's format)",
                          "value": summary["summary_version"]}]
                        if "summary_version" in summary else []),
                      {"item": "page written (UTC)",
                       "value": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S")}],
                     ["item", "value"])]
    path = out / "report.html"
    atomic_write_text(path, _page(title, body))
    return path


def write_study_report(out_dir: str | Path, title: str, rows: list[dict]) -> Path:
    """Write ``OUT/report.html`` of a study: the variants (``rows`` of results.csv, whose
    ``id`` names ``runs/<id>/``) with links to each run's page, and the comparison plots."""
    out = Path(out_dir)
    columns = list(rows[0]) if rows else ["id"]

    def cell(row, column):
        if column == "id" and (out / "runs" / str(row["id"]) / "report.html").exists():
            href = f"runs/{row['id']}/report.html"
            return f'<a href="{escape(href)}">{escape(str(row["id"]))}</a>', ""
        if column == "outcome" and row.get("outcome"):
            return escape(str(row["outcome"])), _status(row["outcome"] in HELD)
        if column == "status":
            return escape(str(row["status"])), _status(row["status"] == "done")
        return None, ""

    body = ['<h2 id="variants">Variants</h2>',
            "<p>Each id links to the run's own page (verdicts, plots, case).</p>",
            *_table(rows, columns, cell),
            '<h2 id="plots">Comparison plots</h2>', *_images(out / "plots")]
    path = out / "report.html"
    atomic_write_text(path, _page(f"{title}: study report", body))
    return path


def write_index(work: str | Path, title: str) -> Path:
    """Write ``WORK/report.html`` linking every run and study page below ``work``, grouped
    by folder; a finished run without a page (run before pages existed) gets one."""
    work = Path(work)
    for summary in sorted(work.rglob("summary.json")):
        if not (summary.parent / "report.html").exists():
            write_run_report(summary.parent)
    groups: dict[str, list[str]] = {}
    for page in sorted(work.rglob("report.html")):
        if page.parent == work:
            continue
        rel = page.relative_to(work).as_posix()
        label = page.parent.relative_to(work).as_posix()
        note = ""
        summary = page.parent / "summary.json"
        if summary.exists():
            s = json.loads(summary.read_text(encoding="utf-8"))
            # the answer, and any check that failed
            marks = [v for v in answer_boxes(s) if v.status != "na"] + [
                v for v in trust_boxes(s) if v.status == "fail"]
            note = " — " + ", ".join(
                (f'<span class="{v.status}-text">' if v.status in ("pass", "fail")
                 else "<span>") + f"{escape(v.name)}: {escape(v.value)}</span>"
                for v in marks)
        groups.setdefault(label.split("/")[0], []).append(
            f'<li><a href="{escape(rel)}">{escape(label)}</a>{note}</li>')
    body = []
    for group, items in groups.items():
        body += [f"<h2>{escape(group)}</h2>", "<ul>", *items, "</ul>"]
    path = work / "report.html"
    atomic_write_text(path, _page(title, body or ["<p>(no pages yet)</p>"]))
    return path
