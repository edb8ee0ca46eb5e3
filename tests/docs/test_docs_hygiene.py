"""The documentation and the code name no folder of one machine, and every link of the
documentation leads to a file of the repository.

- No absolute path of this machine's folders (``/work/…``, ``/tmp/…``, ``/home/…``) in
  docs/, README.md, src/, examples/ or benchmarks/: run folders are named relative to the
  repository. A deliberate usage example (a scratch checkout in ``/tmp`` shown in a usage
  text) is listed in ``USAGE_EXAMPLES`` with the reason it is one.
- Every relative markdown link (``[text](target)``, images included) of README.md and of
  every page under docs/ resolves to a file or folder inside the repository (``#anchors``
  stripped; ``http(s):`` and ``mailto:`` links are not followed).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MACHINE_PATH = re.compile(r"(?<![\w.~$-])/(?:work|tmp|home)/[\w.~-]*")
SCANNED = ("docs", "src", "examples", "benchmarks")
SUFFIXES = {".md", ".py", ".toml", ".txt", ".csv", ".json", ".cfg", ".ini", ".yml", ".yaml"}
# (file, the line's text that holds the path): a usage text, not a folder of this machine
USAGE_EXAMPLES = {
    ("benchmarks/bitwise_state.py", "git worktree add /tmp/base <base commit>"):
        "the usage text's scratch checkout of the base commit",
    ("benchmarks/bitwise_state.py",
     "PYTHONPATH=/tmp/base/src python benchmarks/bitwise_state.py save CASE 300 base.npz"):
        "the same scratch checkout, run",
}
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def scanned_files() -> list[Path]:
    files = [ROOT / "README.md"]
    for top in SCANNED:
        files += [p for p in sorted((ROOT / top).rglob("*"))
                  if p.is_file() and p.suffix in SUFFIXES and ".egg-info" not in str(p)]
    return files


def machine_paths(path: Path) -> list[tuple[int, str]]:
    found = []
    rel = path.relative_to(ROOT).as_posix()
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if MACHINE_PATH.search(line) and (rel, line.strip()) not in USAGE_EXAMPLES:
            found.append((number, line.strip()))
    return found


def test_no_absolute_path_of_this_machine():
    offenders = {p.relative_to(ROOT).as_posix(): machine_paths(p) for p in scanned_files()}
    offenders = {k: v for k, v in offenders.items() if v}
    assert offenders == {}, offenders


def test_the_path_pattern_finds_what_it_is_for():
    """The pattern catches a run folder, a scratch file and a home folder, and leaves
    relative paths, URLs and unit fractions alone."""
    for text in ("--runs /work/runs/lad29", "see /tmp/out.csv", "(/home/user/x)"):
        assert MACHINE_PATH.search(text), text
    for text in ("../runs/lad29", "out/plate/report.html", "https://example.org/tmp/x",
                 "27 1/in", "kg/m^2", "docs/notes/README.md", "$XDG_CACHE_HOME/x"):
        assert not MACHINE_PATH.search(text), text


def test_usage_examples_are_still_there():
    """An allowed usage example that is gone leaves an allowance nobody needs."""
    for (rel, line), why in USAGE_EXAMPLES.items():
        assert line in (ROOT / rel).read_text(encoding="utf-8"), (rel, line, why)


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_links(page: Path) -> list[str]:
    text = page.read_text(encoding="utf-8")
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)  # code blocks show, not link
    return [t for t in LINK.findall(text) if not re.match(r"[a-z][\w+.-]*:", t)
            and not t.startswith("#")]


@pytest.mark.parametrize("page", pages(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_resolves_inside_the_repository(page):
    broken = []
    for target in relative_links(page):
        path = (page.parent / target.split("#", 1)[0]).resolve()
        if not path.is_relative_to(ROOT) or not path.exists():
            broken.append(target)
    assert broken == [], f"{page.relative_to(ROOT)}: {broken}"


def test_the_link_check_sees_links():
    """The pages do link (the check is not vacuous), and a link out of the repository is
    caught as one."""
    assert "docs/index.md" in relative_links(ROOT / "README.md")
    assert len(relative_links(ROOT / "docs" / "index.md")) >= 8
    outside = (ROOT / "docs" / "../../shared/MODEL.md").resolve()
    assert not outside.is_relative_to(ROOT)


THEORY = ROOT / "docs" / "theory.md"
DATE = re.compile(r"\b20\d\d-\d\d(?:-\d\d)?\b")
HASH = re.compile(r"\b(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}\b")


def diary_marks(text: str) -> list[str]:
    """Dates and commit hashes in a manual's text, links to the dated notes left out (a
    note's file name carries its month: docs/notes/2026-11-….md)."""
    text = re.sub(r"\[[^\]]*\]\(notes/[^)]*\)", "", text)
    return DATE.findall(text) + HASH.findall(text)


def test_the_manual_is_under_1500_lines_and_holds_no_diary():
    """docs/theory.md is a manual, not a notebook (issue 37): under 1 500 lines, and no
    date or commit hash in it (what was tried, and when, lives in docs/notes/)."""
    text = THEORY.read_text(encoding="utf-8")
    assert len(text.splitlines()) < 1500
    assert diary_marks(text) == []


def test_the_diary_check_sees_dates_and_hashes():
    """The check above finds a date and a commit hash, and passes a link to a note."""
    assert diary_marks("measured on 2026-11-28 at 14916d7") == ["2026-11-28", "14916d7"]
    assert diary_marks("see [the note](notes/2026-11-mesh-convergence.md)") == []
    assert diary_marks("[notes/2026-11-x.md](notes/2026-11-x.md)") == []
    assert diary_marks("a = 0.1239 mm, 1e-12, deadbeef is no hash but ab12cd3 is") == ["ab12cd3"]
