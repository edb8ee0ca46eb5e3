"""Read a report.html back (html.parser): verdicts, the grouped summary's rows, images,
links, external references; and what a run's page must show, written out independently
of io/report.py."""

from __future__ import annotations

import base64
import io
from dataclasses import dataclass, field
from html.parser import HTMLParser
from pathlib import Path

import matplotlib.image


@dataclass
class Page:
    verdicts: dict[str, dict] = field(default_factory=dict)  # key → {status, text}
    images: list[tuple[str, str]] = field(default_factory=list)  # (alt, src)
    links: list[str] = field(default_factory=list)
    external: list[str] = field(default_factory=list)  # anything fetched from elsewhere
    text: list[str] = field(default_factory=list)
    summary_rows: dict[str, str] = field(default_factory=dict)  # key → its group
    order: list[str] = field(default_factory=list)  # ids and verdict keys, in page order


class _Reader(HTMLParser):
    def __init__(self):
        super().__init__()
        self.page = Page()
        self._verdict = None
        self._depth = 0
        self._group = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.page.order.append(a["id"])
            if a["id"].startswith("summary-"):
                self._group = a["id"][len("summary-"):]
        if tag == "tr" and a.get("data-key") and self._group is not None:
            self.page.summary_rows[a["data-key"]] = self._group
        if tag == "div" and "verdict" in (a.get("class") or "").split():
            self._verdict = a["data-key"]
            self.page.order.append(f"verdict:{self._verdict}")
            self.page.verdicts[self._verdict] = {"status": a["data-status"],
                                                 "class": a["class"], "text": ""}
            self._depth = 0
        elif tag == "div" and self._verdict is not None:
            self._depth += 1
        if tag == "img":
            self.page.images.append((a.get("alt", ""), a.get("src", "")))
        if tag == "a":
            self.page.links.append(a.get("href", ""))
        if tag in ("script", "link", "iframe") or (
                tag in ("img", "script") and not (a.get("src") or "").startswith("data:")):
            self.page.external.append(f"<{tag} {a}>")

    def handle_endtag(self, tag):
        if tag == "div" and self._verdict is not None:
            if self._depth == 0:
                self._verdict = None
            else:
                self._depth -= 1

    def handle_data(self, data):
        self.page.text.append(data)
        if self._verdict is not None:
            self.page.verdicts[self._verdict]["text"] += data


def read_page(path: Path) -> Page:
    reader = _Reader()
    reader.feed(Path(path).read_text(encoding="utf-8"))
    reader.close()
    return reader.page


def decoded_images(page: Page) -> dict[str, tuple]:
    """alt → (height, width) of every inlined PNG, decoded (fails on a broken image)."""
    out = {}
    for alt, src in page.images:
        head, _, data = src.partition(",")
        assert head == "data:image/png;base64", f"{alt}: not an inline PNG ({head[:40]})"
        img = matplotlib.image.imread(io.BytesIO(base64.b64decode(data, validate=True)),
                                      format="png")
        out[alt] = img.shape[:2]
    return out


CONTAINMENT = "fragment_exit_speed_m_per_s"  # the key that makes a summary a containment's
ANSWER_BOXES = {"containment": {"outcome", "fragment_exit_speed_m_per_s",
                                "casing_absorbed_energy_J", "max_bulge_m"},
                "plate": {"outcome", "residual_velocity_m_per_s", "absorbed_energy_J",
                          "max_deflection_m"},
                "no impactor": {"outcome", "max_displacement_m"}}
TRUST_BOXES = {"mesh_verdict", "energy_error_fraction", "hourglass_fraction",
               "added_mass_fraction", "outcome_settled"}
INFO = ("casing_absorbed_energy_J", "max_bulge_m", "absorbed_energy_J", "max_deflection_m",
        "max_displacement_m")


def kind(summary: dict) -> str:
    if CONTAINMENT in summary or "casing_layers" in summary:
        return "containment"
    return "plate" if "outcome" in summary or "residual_velocity_m_per_s" in summary else (
        "no impactor")


def expected_status(summary: dict, key: str) -> str:
    """The box a summary deserves, written out independently of io/report.py: green or
    red by the rule, blue for a figure without one, grey when there is no value."""
    containment = kind(summary) == "containment"
    outcome = summary.get("outcome")
    if key == "outcome_settled":
        if outcome is None:
            return "na"
        if outcome == "undecided":
            return "fail"
        if not containment or outcome != "escaped":
            return "pass"
        settled = summary.get("fragment_exit_speed_settled")
        return "na" if settled is None else "pass" if settled else "fail"
    if key == "added_mass_fraction":
        return "pass" if summary.get(key) is None or summary[key] <= 0.02 else "fail"
    v = summary.get(key)
    if v is None:
        return "na"
    if key in INFO:
        return "info"
    if key == "mesh_verdict" and not v:  # no failing material
        return "na"
    rule = {"outcome": lambda: v == ("contained" if containment else "stopped"),
            "residual_velocity_m_per_s": lambda: v == 0.0,
            "fragment_exit_speed_m_per_s": lambda: v == 0.0,
            "energy_error_fraction": lambda: v <= summary.get("energy_tolerance", 0.01),
            "hourglass_fraction": lambda: v <= 0.10,
            # every failing material at its reference size or in its calibrated range
            "mesh_verdict": lambda: all(m["ok"] for m in v.values())}
    ok = rule[key]()
    return "pass" if ok else "fail"


def check_run_page(out: Path) -> Page:
    """Every assertion a run page must pass against its summary.json and plots/."""
    import json

    page = read_page(out / "report.html")
    summary = json.loads((out / "summary.json").read_text())
    assert not page.external, page.external
    pngs = sorted(p.name for p in (out / "plots").glob("*.png"))
    # the deformed structure's pictures (pictures.json lists those shown), then the plots
    index = out / "pictures" / "pictures.json"
    pictures = [e["file"] for e in json.loads(index.read_text())] if index.exists() else []
    assert pngs and sorted(decoded_images(page)) == sorted(pngs + pictures)
    assert set(page.verdicts) == ANSWER_BOXES[kind(summary)] | TRUST_BOXES
    for key, v in page.verdicts.items():
        assert v["status"] == expected_status(summary, key), (key, v, summary.get(key))
        assert v["status"] in v["class"].split()
        if v["status"] == "na":  # no value, or none yet (an undecided fragment's exit speed)
            assert "n/a" in v["text"] or "none: undecided" in v["text"], v
    if "outcome" in summary:
        assert summary["outcome"] in page.verdicts["outcome"]["text"]
    # the answer, then the trust block, then the grouped summary (every key but the
    # internal ones, each in one group), then the plots
    order = page.order
    answers = [order.index(f"verdict:{k}") for k in ANSWER_BOXES[kind(summary)]]
    trusts = [order.index(f"verdict:{k}") for k in TRUST_BOXES]
    assert max(answers) < order.index("trust") < min(trusts)
    assert max(trusts) < order.index("summary") < order.index("plots")
    assert set(page.summary_rows) == set(summary) - {"summary_version", "provenance"}
    return page
