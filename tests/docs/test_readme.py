"""The README is tested: every fenced block of README.md is run or parsed, so it cannot rot.

Blocks, and what is done with them:

- shell blocks (no language): each ``$ `` line is a command (``\\`` continues it, ``#``
  starts a comment); the lines under a command are its expected output, each of which
  must match a line it printed (``...`` stands for more digits). ``make TARGET`` must be
  a target of the Makefile (it is not run: ``make run`` is the full flagship, ``make
  test`` runs this file). ``.venv/bin/wovenimpact ARGS`` runs in-process (typer's
  CliRunner) in a scratch directory where ``examples/`` is the repository's, and must
  exit with 0.
- ``toml`` blocks: one with a ``[case]`` table is a whole case, validated by the case
  loader with its materials relative to ``examples/cases/`` and compiled; the tour's
  must be ``examples/cases/fabric_plate_impulse.toml`` (same spec but for the
  description). Any other ``toml`` block is a fragment added to the case before it
  (validated and compiled together).
- ``python`` blocks are executed in the scratch directory.

An HTML comment on the line above a block's fence steers it (invisible on GitHub):

- ``<!-- test: --set KEY=VALUE ... -->``: appended to every command of the block
  (shortened runs on coarse meshes);
- ``<!-- test: given PATH ... (where) -->``: these files, from tests/docs/given/PATH, are
  put in the scratch directory first;
- ``<!-- test: skip (reason) -->``: the commands are not run, but every option they use
  must be listed by the command's ``--help``.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import shutil
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from typer.testing import CliRunner

from wovenimpact.cli.app import app
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import case_from_dict, load_case

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
GIVEN = Path(__file__).resolve().parent / "given"
CLI = ".venv/bin/wovenimpact"
FENCE = re.compile(r"(?:<!-- test: (?P<directive>.*?) -->\n)?^```(?P<lang>\w*)\n(?P<body>.*?)^```",
                   re.S | re.M)


@dataclass
class Command:
    line: int
    argv: list[str]
    expected: list[str] = field(default_factory=list)


@dataclass
class Block:
    line: int
    lang: str
    body: str
    directive: str = ""

    def commands(self) -> list[Command]:
        """The ``$`` commands of a shell block with the output lines shown under each."""
        out, pending = [], None
        lines = self.body.splitlines()
        for i, text in enumerate(lines):
            if pending is not None:
                pending.append(text)
                if not text.endswith("\\"):
                    out[-1].argv = shlex.split(" ".join(t.rstrip("\\") for t in pending),
                                               comments=True)
                    pending = None
            elif text.startswith("$ "):
                out.append(Command(self.line + 1 + i, []))
                pending = [text[2:]]
                if not text.endswith("\\"):
                    out[-1].argv = shlex.split(text[2:], comments=True)
                    pending = None
            elif text.strip() and out:
                out[-1].expected.append(text)
        return out

    def extra_args(self) -> list[str]:
        return shlex.split(self.directive) if self.directive.startswith("--") else []


def readme_blocks() -> list[Block]:
    text = README.read_text(encoding="utf-8")
    return [Block(text.count("\n", 0, m.start("body")), m["lang"], m["body"],
                  (m["directive"] or "").strip())
            for m in FENCE.finditer(text)]


BLOCKS = readme_blocks()
SHELL = [b for b in BLOCKS if b.lang == ""]


def output_pattern(shown: str) -> re.Pattern:
    """A README output line as a pattern: literal, except ``...`` (more digits)."""
    return re.compile(r"\s*" + r"\d*".join(re.escape(p) for p in shown.strip().split("..."))
                      + r"\s*")


def test_the_readme_has_the_blocks_this_test_knows():
    langs = [b.lang for b in BLOCKS]
    assert set(langs) <= {"", "toml", "python"}, langs
    assert langs.count("toml") >= 2 and "python" in langs and len(SHELL) >= 6
    assert all(b.commands() for b in SHELL), "a shell block without a $ command"
    for b in BLOCKS:
        assert b.directive == "" or re.match(r"(--set |given |skip \()", b.directive), b.directive


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    """A directory like a fresh clone's for the commands: examples/ is the repository's."""
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def makefile_targets() -> set[str]:
    text = (ROOT / "Makefile").read_text()
    return set(re.findall(r"^([A-Za-z][\w-]*):", text, re.M))


@pytest.mark.parametrize("block", SHELL, ids=lambda b: f"README.md:{b.line}")
def test_shell_block(block: Block, scratch: Path):
    if block.directive.startswith("given "):
        for rel in block.directive.split("(")[0].split()[1:]:
            (scratch / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(GIVEN / rel, scratch / rel)
    for cmd in block.commands():
        where = f"README.md:{cmd.line}: {shlex.join(cmd.argv)}"
        if cmd.argv[0] == "make":
            assert cmd.argv[1] in makefile_targets(), where
            continue
        assert cmd.argv[0] == CLI, f"{where}: commands run through {CLI}"
        args = cmd.argv[1:]
        if block.directive.startswith("skip ("):
            check_options_exist(args, where)
            continue
        result = CliRunner().invoke(app, args + block.extra_args())
        assert result.exit_code == 0, f"{where}\n{result.output}\n{result.exception!r}"
        printed = result.stdout.splitlines()
        for shown in cmd.expected:
            pattern = output_pattern(shown)
            assert any(pattern.fullmatch(p) for p in printed), (
                f"{where}: README shows {shown!r}; printed:\n{result.stdout}")


def check_options_exist(args: list[str], where: str) -> None:
    """A command not run: its sub-command exists and lists every option used."""
    words = [a for a in args if not a.startswith("-")]
    sub = [w for w in words[:2] if w in ("design", "plies", "sweep", "run", "ballistics",
                                         "calibrate", "crimp", "compression", "fracture",
                                         "element-test", "validate", "bench")]
    result = CliRunner().invoke(app, [*sub, "--help"], terminal_width=200)
    assert result.exit_code == 0, f"{where}: {result.output}"
    for a in args:
        if a.startswith("--"):
            assert a.split("=")[0] in result.output, f"{where}: {a} is not an option"


def test_run_commands_write_the_pages_the_readme_promises(scratch):
    """The tour's run leaves report.html (and the files named) in out/plate; the sweep's
    page links its runs'. (Run here once more, shortened, to look at the files.)"""
    from tests.io.report_page import check_run_page, read_page

    tour = next(b for b in SHELL if "fabric_plate_impulse.toml" in b.body)
    first = tour.commands()[0]
    result = CliRunner().invoke(app, first.argv[1:] + tour.extra_args())
    assert result.exit_code == 0, result.output
    out = scratch / "out" / "plate"
    for name in ("report.html", "history.csv", "summary.json", "plots/energy.png",
                 "fields/fields.pvd"):
        assert (out / name).exists(), name
    assert "report: out/plate/report.html" in result.stdout
    check_run_page(out)
    assert not read_page(out / "report.html").external


TOML = [b for b in BLOCKS if b.lang == "toml"]


def test_toml_blocks_are_valid_cases_and_the_tour_is_the_example(recwarn):
    cases_dir = ROOT / "examples" / "cases"
    case_doc = None
    for block in TOML:
        doc = tomllib.loads(block.body)
        where = f"README.md:{block.line}"
        if "case" in doc:
            case_doc = doc
        else:
            assert case_doc is not None, f"{where}: a fragment before any whole case"
            doc = {**case_doc, **doc}
        spec = case_from_dict(doc, source=where)
        compiled = compile_case(spec, cases_dir)
        assert compiled.model.n_elems > 0, where
    assert not [w for w in recwarn if "README" in str(w.message)], "a README case warns"
    tour = case_from_dict(tomllib.loads(TOML[0].body), source="README tour")
    example, _ = load_case(cases_dir / "fabric_plate_impulse.toml")
    shown, real = tour.model_dump(), example.model_dump()
    shown["case"].pop("description"), real["case"].pop("description")
    assert shown == real, "the tour's case is not examples/cases/fabric_plate_impulse.toml"
    a = compile_case(tour, cases_dir).model
    b = compile_case(example, cases_dir).model
    assert (a.bc_code == b.bc_code).all()  # the same constraints (clamp and symmetry)


@pytest.mark.parametrize("block", [b for b in BLOCKS if b.lang == "python"],
                         ids=lambda b: f"README.md:{b.line}")
def test_python_block(block: Block, scratch):
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(block.body, f"README.md:{block.line}", "exec"), {"__name__": "readme"})
    assert printed.getvalue().strip(), "the snippet prints its result"


# a wall time or duration as a README would state one: "16.3 s", "about 5 minutes", "2 h"
# (simulated times are written in us or ms, which this does not match)
DURATION = re.compile(r"\b\d+(?:\.\d+)?\s?(?:s|sec|seconds?|min|minutes?|h|hours?)\b")


def test_the_readme_states_no_run_times():
    """Wall times live on docs/performance.md, with the machine they were taken on; a
    README that quotes them goes stale with every change of code or machine."""
    text = README.read_text(encoding="utf-8")
    assert DURATION.findall(text) == [], DURATION.findall(text)


def test_the_flagship_time_is_on_the_performance_page_with_its_machine():
    """The flagship's time is stated in the flagship section of docs/performance.md, next to
    the machine line (CPU, cores, versions, date) of the run that measured it."""
    page = (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    section = re.search(r"<!-- section: flagship -->\n(.*?)<!-- end section: flagship -->",
                        page, re.S)
    assert section, "docs/performance.md has no flagship section"
    text = section[1]
    assert "plies4_120" in text, "the flagship section does not name the flagship case"
    assert re.search(r"\d+(?:\.\d+)?\s?s\**\s+of run", text), "no wall time of the run"
    assert re.search(r"`machine: [^`]+, \d+ cores \(\d+ Numba threads\), [^`]+, "
                     r"\d{4}-\d\d-\d\d`", text), "no machine line with its date"


def code_map() -> dict[str, set[str]]:
    """The README's code map: where (a package ``name/`` or ``top level``) → modules named."""
    text = README.read_text(encoding="utf-8").split("## Code map", 1)[1]
    out = {}
    for where, modules in re.findall(r"^\| `?([\w ]+/?)`? \| (.*?) \| .* \|$", text, re.M):
        if where in ("where",):
            continue
        out[where] = set(re.findall(r"`([\w.]+)`", modules))
    return out


def test_the_code_map_names_every_module_and_nothing_else():
    """Each package of src/wovenimpact is a row naming all its modules, and the top-level
    row names every top-level module (``name.py``); a module added, moved or removed without
    the map following fails here."""
    src = ROOT / "src" / "wovenimpact"
    actual = {f"{p.name}/": {m.stem for m in p.glob("*.py") if m.stem != "__init__"}
              for p in sorted(src.iterdir()) if (p / "__init__.py").is_file()}
    actual["top level"] = {m.name for m in src.glob("*.py") if m.stem != "__init__"}
    assert code_map() == actual


def test_make_run_ends_by_printing_the_flagships_report_path():
    text = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^run:.*\n((?:\t.*\n)+)", text, re.M)[1].splitlines()
    flagship = next(line for line in recipe if "wovenimpact run " in line)
    out = re.search(r"--out (\S+)", flagship)[1]
    assert recipe[-1].strip().startswith("@echo") and f"{out}/report.html" in recipe[-1]
