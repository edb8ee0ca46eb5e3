"""report.html in a real browser: a run's page opened in headless Chromium (tests/io/browser.py)
loads every image and shows every verdict box, coloured by its status and with its text,
and the answer and the trust block fit a 1280 × 900 window without scrolling.

The run is the coarse two-ply pack perforated at 900 m/s of test_pictures.py (a few seconds:
pictures and plots). Skipped where no Chromium is found; `make test` installs Debian's
``chromium-headless-shell`` when it runs as root with apt-get, as in CI. The last test breaks
a copy of the page (an image's path, an image's data, the styles) and checks that each
break is caught, so the checks cannot pass on a page the browser did not render.
"""

from __future__ import annotations

import re
import warnings

import pytest

from tests.io.browser import WINDOW, find_chromium, open_in_browser
from tests.io.report_page import read_page
from tests.io.test_pictures import CASE, PERFORATING
from wovenimpact.runs import run_case

CHROMIUM = find_chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no Chromium found (chromium or chromium-headless-shell on the "
    "PATH, or WOVENIMPACT_CHROMIUM); `make test` installs it as root with apt-get")

# each status's box colour (report.py's CSS), as the browser computes it
BACKGROUND = {"pass": "rgb(46, 125, 50)", "fail": "rgb(198, 40, 40)",
              "info": "rgb(21, 101, 192)", "na": "rgb(117, 117, 117)"}
WHITE = "rgb(255, 255, 255)"


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("browser") / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the coarse mesh's warnings are not under test
        run_case(CASE, out, overrides=PERFORATING)
    return out / "report.html"


def letters(text: str) -> str:
    return re.sub(r"\s+", "", text)


def check_rendered(seen: dict, page) -> None:
    """What the browser shows of ``page`` (read_page's reading of the same file)."""
    assert seen["viewport"] == list(WINDOW)
    # every image loaded and decoded, and drawn with a size
    assert len(seen["images"]) == len(page.images) > 0
    broken = [i["alt"] for i in seen["images"]
              if not (i["complete"] and i["natural_width"] > 0 and i["natural_height"] > 0)]
    assert broken == [], f"images that did not load: {broken}"
    hidden = [i["alt"] for i in seen["images"] if i["box"]["width"] <= 0]
    assert hidden == [], f"images not drawn: {hidden}"
    # every verdict box shown, in its status's colour, white text, with its text
    assert [v["key"] for v in seen["verdicts"]] == list(page.verdicts)
    for v in seen["verdicts"]:
        b = v["box"]
        assert b["display"] != "none" and b["visibility"] == "visible", v
        assert b["width"] > 50 and b["height"] > 20, v
        assert b["background"] == BACKGROUND[v["status"]], (
            f"{v['key']}: background {b['background']}, not {v['status']}'s colour")
        assert b["color"] == WHITE, f"{v['key']}: text colour {b['color']}"
        # the text read off the file, as the browser lays it out (a line per block)
        assert letters(v["text"]) and letters(v["text"]) == letters(
            page.verdicts[v["key"]]["text"]), f"{v['key']}: shows {v['text']!r}"


def test_the_page_renders_in_chromium(report, tmp_path):
    """Every image loads (naturalWidth > 0) and is drawn; every answer and trust box is
    visible with its text and its status's colour."""
    page = read_page(report)
    seen = open_in_browser(report, tmp_path, CHROMIUM)
    check_rendered(seen, page)
    answers = [v for v in seen["verdicts"] if not v["in_trust"]]
    trusts = [v for v in seen["verdicts"] if v["in_trust"]]
    assert [v["key"] for v in answers][0] == "outcome" and len(trusts) == 5
    assert any(v["key"] == "mesh_verdict" for v in trusts)
    assert "perforated" in answers[0]["text"]
    # pictures and plots are images in the page: at least one of each section
    assert len(seen["images"]) >= 4


def test_the_answer_and_the_trust_block_need_no_scrolling(report, tmp_path):
    """In a 1280 × 900 window the answer boxes, the mesh verdict and the whole trust block
    (boxes, element size and overrides) lie above the fold."""
    seen = open_in_browser(report, tmp_path, CHROMIUM)
    fold = WINDOW[1]
    for v in seen["verdicts"]:
        assert v["box"]["bottom"] <= fold, (v["key"], v["box"]["bottom"])
    assert seen["sections"]["trust"]["bottom"] <= fold, seen["sections"]["trust"]
    assert seen["sections"]["summary"]["top"] > seen["sections"]["trust"]["bottom"]


def _break_path(html: str) -> str:  # the first image points at a file that is not there
    return re.sub(r'src="data:image/png;base64,[^"]*"', 'src="pictures/missing.png"', html,
                  count=1)


def _break_data(html: str) -> str:  # the first image's PNG cut short: it cannot decode
    return re.sub(r'(src="data:image/png;base64,)([^"]{64})[^"]*"', r'\1\2"', html, count=1)


def _break_styles(html: str) -> str:  # the page's CSS lost: the boxes have no colour
    return re.sub(r"<style>.*?</style>", "", html, count=1, flags=re.S)


@pytest.mark.parametrize("damage, caught", [(_break_path, "images that did not load"),
                                            (_break_data, "images that did not load"),
                                            (_break_styles, "background")])
def test_a_broken_page_fails_the_check(report, tmp_path, damage, caught):
    """The checks fail on a page the browser cannot render as written."""
    broken = tmp_path / "broken" / "report.html"
    broken.parent.mkdir()
    text = report.read_text(encoding="utf-8")
    damaged = damage(text)
    assert damaged != text
    broken.write_text(damaged, encoding="utf-8")
    seen = open_in_browser(broken, tmp_path / "scratch", CHROMIUM)
    with pytest.raises(AssertionError, match=caught):
        check_rendered(seen, read_page(broken))
