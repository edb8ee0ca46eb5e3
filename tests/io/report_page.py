"""Read a report.html back (html.parser): verdicts, images, links, external references."""

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


class _Reader(HTMLParser):
    def __init__(self):
        super().__init__()
        self.page = Page()
        self._verdict = None
        self._depth = 0

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "div" and "verdict" in (a.get("class") or "").split():
            self._verdict = a["data-key"]
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


def expected_status(summary: dict, key: str) -> str:
    """The verdict a summary deserves, written out independently of io/report.py (a
    containment run's residual velocity is its fragment's exit speed)."""
    v = summary.get(key)
    if key == "residual_velocity_m_per_s" and v is None:
        v = summary.get("fragment_exit_speed_m_per_s")
    if v is None:
        return "na"
    if key == "mesh_verdict" and not v:  # no failing material
        return "na"
    rule = {"outcome": lambda: v in ("stopped", "contained"),
            "residual_velocity_m_per_s": lambda: v == 0.0,
            "energy_error_fraction": lambda: v <= 0.01, "hourglass_fraction": lambda: v <= 0.10,
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
    assert pngs and sorted(decoded_images(page)) == pngs
    assert set(page.verdicts) == {"outcome", "residual_velocity_m_per_s",
                                  "energy_error_fraction", "hourglass_fraction", "mesh_verdict"}
    for key, v in page.verdicts.items():
        assert v["status"] == expected_status(summary, key), (key, v, summary.get(key))
        assert v["status"] in v["class"].split()
        if v["status"] == "na":
            assert "n/a" in v["text"]
    if "outcome" in summary:
        assert summary["outcome"] in page.verdicts["outcome"]["text"]
    return page
