"""``report.html``: one self-contained page per run, per study and per validation.

A run's page sits beside its ``summary.json`` and answers "did it hold, and can I trust
the run" before anything else:

1. the verdicts, each green (``pass``), red (``fail``) or grey (``n/a``, key absent):
   outcome (green when the impactor was stopped, or a blade fragment contained),
   residual velocity (a fragment's exit speed; green at 0, with the rebound velocity), energy error against :data:`ENERGY_ERROR_LIMIT` (1 %) and
   hourglass share ``hourglass_fraction`` against :data:`HOURGLASS_LIMIT` (10 %), and the
   mesh: each failing material's element lengths against the range its failure law is
   calibrated for (:mod:`wovenimpact.mesh_verdict`; red for a law that is not
   regularised, on elements away from its reference size);
2. the whole summary as a table;
3. every PNG of ``plots/``, inlined as base64;
4. the case as run: the TOML text with the ``--set`` overrides (a study variant: the
   validated case as JSON, in SI units, and its parameters);
5. provenance: code version, a digest of the case text, the model digest.

The page needs no network: CSS and images are inline, nothing is fetched. A study's
page (``OUT/report.html`` of a sweep) tabulates the variants with links to each run's
page and inlines the comparison plots; :func:`write_index` links every page under a
directory (``wovenimpact validate``). Each verdict is an element
``<div class="verdict pass|fail|na" data-key=KEY data-value=VALUE>``, so a test (or a
script) can read the page back.
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

ENERGY_ERROR_LIMIT = 0.01  # largest energy-balance error fraction of a trusted run
HOURGLASS_LIMIT = 0.10  # largest hourglass energy / internal work of a trusted run

CSS = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 70em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 2em; }
.verdicts { display: flex; flex-wrap: wrap; gap: 0.8em; }
.verdict { border-radius: 6px; padding: 0.6em 1em; min-width: 13em; color: #fff; }
.verdict .name { font-size: 0.85em; opacity: 0.9; } .verdict .value { font-size: 1.3em; }
.pass { background: #2e7d32; } .fail { background: #c62828; } .na { background: #757575; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: 0.2em 0.6em; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.pass { color: #2e7d32; font-weight: bold; background: none; }
td.fail { color: #c62828; font-weight: bold; background: none; }
img { max-width: 100%; display: block; margin: 1em 0; }
pre { background: #f5f5f5; padding: 1em; overflow-x: auto; }
.pass-text { color: #2e7d32; } .fail-text { color: #c62828; }
"""


@dataclass(frozen=True)
class Verdict:
    """One answer of a run: ``status`` is "pass", "fail" or "na" (its key is absent)."""

    key: str
    name: str
    value: str
    threshold: str
    status: str


def _status(ok: bool | None) -> str:
    return "na" if ok is None else ("pass" if ok else "fail")


HELD = ("stopped", "contained")  # the outcomes that mean the structure held


def verdicts(summary: dict) -> list[Verdict]:
    """The verdicts of a run's summary (see the module docstring for the rules)."""
    outcome = summary.get("outcome")
    residual = summary.get("residual_velocity_m_per_s",
                           summary.get("fragment_exit_speed_m_per_s"))
    rebound = summary.get("rebound_velocity_m_per_s")
    error = summary.get("energy_error_fraction")
    limit = summary.get("energy_tolerance", ENERGY_ERROR_LIMIT)  # the run's own, if given
    hourglass = summary.get("hourglass_fraction")
    residual_text = "n/a" if residual is None else f"{residual:.2f} m/s"
    if rebound is not None:
        residual_text += f" (rebound {rebound:.2f} m/s)"
    # a containment run's second box is its fragment's exit speed (none when contained)
    fragment = "residual_velocity_m_per_s" not in summary and (
        "fragment_exit_speed_m_per_s" in summary)
    speed_name, speed_limit = (("fragment exit speed", "none: contained") if fragment
                               else ("residual velocity", "0 m/s"))
    return [
        Verdict("outcome", "outcome", "n/a" if outcome is None else str(outcome),
                " or ".join(HELD), _status(None if outcome is None else outcome in HELD)),
        Verdict("residual_velocity_m_per_s", speed_name, residual_text, speed_limit,
                _status(None if residual is None else residual == 0.0)),
        Verdict("energy_error_fraction", "energy error",
                "n/a" if error is None else f"{error * 100:.2g} %", f"≤ {limit * 100:.2g} %",
                _status(None if error is None else error <= limit)),
        Verdict("hourglass_fraction", "hourglass share of internal work",
                "n/a" if hourglass is None else f"{hourglass:.1%}", f"≤ {HOURGLASS_LIMIT:.0%}",
                _status(None if hourglass is None else hourglass <= HOURGLASS_LIMIT)),
        mesh_box(summary),
    ]


MESH_THRESHOLD = "failure calibrated for these elements; the striker's edge resolved"


def mesh_box(summary: dict) -> Verdict:
    """The mesh verdict (:mod:`wovenimpact.mesh_verdict`): green when every failing
    material's elements lie at its reference size or within its calibrated range."""
    from wovenimpact.mesh_verdict import SUMMARY_KEY, verdict_text

    found = summary.get(SUMMARY_KEY)
    if found is None:
        return Verdict(SUMMARY_KEY, "mesh", "n/a", MESH_THRESHOLD, "na")
    text, ok = verdict_text(found)
    return Verdict(SUMMARY_KEY, "mesh", text, MESH_THRESHOLD, _status(ok))


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
    return (f'<div class="verdict {v.status}" data-key="{escape(v.key)}" '
            f'data-status="{v.status}"><div class="name">{escape(v.name)} '
            f'(threshold {escape(v.threshold)})</div><div class="value">{escape(v.value)}'
            "</div></div>")


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
    body = ['<h2 id="verdicts">Verdicts</h2>', '<div class="verdicts">',
            *(_verdict_html(v) for v in verdicts(summary)), "</div>",
            '<h2 id="summary">Summary</h2>',
            *_table([{"quantity": k, "value": v} for k, v in summary.items()],
                    ["quantity", "value"]),
            '<h2 id="plots">Plots</h2>', *_images(out / "plots"),
            '<h2 id="case">Case as run</h2>']
    if case_text is not None:
        shown = case_text
        body.append(f"<p>{escape(str(case_path or 'case file'))}</p>")
    elif spec is not None:
        shown = spec.model_dump_json(indent=2)
        body.append("<p>The validated case (every quantity in SI units).</p>")
    else:
        shown = ""
        body.append("<p>(the case is not known to this page)</p>")
    if shown:
        body.append(f'<pre class="case">{escape(shown)}</pre>')
    parameters = out / "parameters.json"
    if parameters.exists():
        overrides = [f"{k}={json.dumps(v)}" for k, v in
                     json.loads(parameters.read_text(encoding="utf-8")).items()]
    body.append("<p>Overrides (--set / study parameters): "
                + (", ".join(f"<code>{escape(o)}</code>" for o in overrides) or "none")
                + "</p>")
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
            marks = [v for v in verdicts(s) if v.status != "na"]
            note = " — " + ", ".join(f'<span class="{"pass" if v.status == "pass" else "fail"}'
                                     f'-text">{escape(v.name)}: {escape(v.value)}</span>'
                                     for v in marks)
        groups.setdefault(label.split("/")[0], []).append(
            f'<li><a href="{escape(rel)}">{escape(label)}</a>{note}</li>')
    body = []
    for group, items in groups.items():
        body += [f"<h2>{escape(group)}</h2>", "<ul>", *items, "</ul>"]
    path = work / "report.html"
    atomic_write_text(path, _page(title, body or ["<p>(no pages yet)</p>"]))
    return path
