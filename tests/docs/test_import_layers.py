"""The import layers of docs/architecture.md hold in the code: every module of
src/wovenimpact belongs to a part of the layers table, imports only parts of lower layers
that its row lists (imports inside functions included), and no two modules import each
other. The table is read from the page, so the page and the code cannot drift apart."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "wovenimpact"
PAGE = ROOT / "docs" / "architecture.md"
ROW = re.compile(r"^\| (\d+) \| (`[^|]*`) \| [^|]* \| ([^|]*) \|$", re.M)
PACKAGE_ROOT = "__init__"  # the part `__init__.py`: the package's own module


def _part_name(cell: str) -> str:
    """`cli/`, `runs.py`, `kernels`, `__init__.py` → cli, runs, kernels, __init__."""
    return cell.removesuffix("/").removesuffix(".py")


def layers_table(text: str) -> dict[str, tuple[int, set[str]]]:
    """part → (layer, the parts it may import), from the page's table."""
    table = {}
    for layer, parts, imports in ROW.findall(text):
        allowed = {_part_name(n) for n in re.findall(r"`([^`]+)`", imports)}
        for name in re.findall(r"`([^`]+)`", parts):
            assert _part_name(name) not in table, f"{name} is in two rows"
            table[_part_name(name)] = (int(layer), allowed)
    return table


def modules(src: Path = SRC) -> dict[str, Path]:
    """Dotted name → file of every module of the package (a package is its __init__)."""
    out = {}
    for path in sorted(src.rglob("*.py")):
        parts = list(path.relative_to(src.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def _resolve(name: str, known) -> str | None:
    """The module ``name`` is, or lies in (an attribute imported from a module)."""
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def imports_of(module: str, path: Path, known) -> set[str]:
    """The package's modules ``module`` imports, anywhere in its code (a function's
    deferred imports too); ``from a import b`` counts as a.b when that is a module."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from the module's package
                package = module.split(".")[: None if path.name == "__init__.py" else -1]
                package = package[: len(package) - node.level + 1]
                base = ".".join(package + ([base] if base else []))
            names = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base
                     for a in node.names]
        else:
            continue
        out |= {_resolve(n, known) for n in names if n.split(".")[0] == "wovenimpact"}
    out.discard(None)
    out.discard(module)
    return out


def part_of(module: str) -> str:
    """wovenimpact.solver.explicit → solver; wovenimpact.runs → runs; wovenimpact →
    __init__."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else PACKAGE_ROOT


def import_graph(src: Path = SRC) -> dict[str, set[str]]:
    known = modules(src)
    return {m: imports_of(m, p, known) for m, p in known.items()}


def layer_breaks(graph: dict[str, set[str]], table) -> list[str]:
    """Each import against the table, and each module of no part, in words."""
    out = []
    for module, targets in sorted(graph.items()):
        part = part_of(module)
        if part not in table:
            out.append(f"{module}: its part {part!r} is in no row of the layers table")
            continue
        layer, allowed = table[part]
        for target in sorted(targets):
            other = part_of(target)
            if other == part:
                continue
            if other not in table:
                out.append(f"{module} imports {target}, of no part of the table")
            elif table[other][0] >= layer:
                out.append(f"{module} (layer {layer}) imports {target} (layer "
                           f"{table[other][0]}): not below it")
            elif other not in allowed:
                out.append(f"{module} imports {target}: {other!r} is not in the row of "
                           f"{part!r}")
    return out


def circles(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """Pairs of modules that import each other."""
    return sorted({tuple(sorted((a, b))) for a, targets in graph.items() for b in targets
                   if a in graph.get(b, ())})


def test_every_import_follows_the_layers_of_the_architecture_page():
    breaks = layer_breaks(import_graph(), layers_table(PAGE.read_text(encoding="utf-8")))
    assert not breaks, "\n".join(breaks)


def test_no_two_modules_import_each_other():
    found = circles(import_graph())
    assert not found, "\n".join(f"{a} and {b} import each other" for a, b in found)


def test_the_table_is_read_whole():
    """Every part of the package is a row (a package or module added without a row
    fails in the test above), and the rows the page gives are all found."""
    table = layers_table(PAGE.read_text(encoding="utf-8"))
    assert {"kernels", "solver", "setup", "results", "cli", "runs", PACKAGE_ROOT} <= set(table)
    assert table["kernels"] == (2, {"jit"})
    assert table["errors"][1] == set()


@pytest.fixture
def package(tmp_path):
    """A small package laid out like src/wovenimpact, to show that the checks fail."""
    src = tmp_path / "wovenimpact"
    for rel, code in {
        "__init__.py": "",
        "low.py": "",
        "mid/__init__.py": "",
        "mid/a.py": "from wovenimpact import low\n",
        "mid/b.py": "def f():\n    from wovenimpact.mid.a import x\n",
        "top.py": "from wovenimpact.mid import b\n",
    }.items():
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        (src / rel).write_text(code)
    table = {"low": (0, set()), "mid": (1, {"low"}), "top": (2, {"mid"}),
             PACKAGE_ROOT: (0, set())}
    return src, table


def test_the_checks_fail_on_an_upward_import_and_on_a_circle(package):
    src, table = package
    assert layer_breaks(import_graph(src), table) == [] and circles(import_graph(src)) == []
    (src / "low.py").write_text("def f():\n    from wovenimpact.top import g\n")  # deferred
    assert layer_breaks(import_graph(src), table) == [
        "wovenimpact.low (layer 0) imports wovenimpact.top (layer 2): not below it"]
    (src / "mid" / "a.py").write_text("from wovenimpact.mid import b\n")
    assert circles(import_graph(src)) == [("wovenimpact.mid.a", "wovenimpact.mid.b")]
    (src / "stray.py").write_text("")
    assert "wovenimpact.stray: its part 'stray' is in no row of the layers table" in \
        layer_breaks(import_graph(src), table)
