"""No function of the package outside ``kernels/`` longer than MAX_LINES lines, unless it
says why.

A function that long does several jobs, and a reader must hold them all at once: split it
into helpers that each build one thing (``model.model.build_model``,
``setup.compile.compile_case``). A function may stay long only where a comment just above
its ``def`` (or above its first decorator) says why, starting with LONG_MARK — for
example ``# long: one pass over the nodes, the order of its stages is the algorithm``.

Kernels (``kernels/``) are left out: a Numba kernel inlines its stages into one parallel
loop on purpose (tests/docs/test_kernel_calls.py). A function's length is counted from its
``def`` line to its last line, docstring and comments included.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "wovenimpact"
KERNELS = PACKAGE / "kernels"
MAX_LINES = 120
LONG_MARK = "# long:"
# Functions being split by someone else's open work (issue 37): each is named with the
# reason it may still be long; an entry that is no longer long fails the second test, so
# the list only shrinks.
PENDING: dict[str, str] = {}


def long_functions(path: Path) -> list[tuple[str, int, bool]]:
    """(qualified name, lines, whether a comment above its def starts with LONG_MARK) of
    every function or method in the file at ``path`` longer than MAX_LINES lines, nested
    ones included."""
    lines = path.read_text(encoding="utf-8").splitlines()
    found = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    length = child.end_lineno - child.lineno + 1
                    if length > MAX_LINES:
                        first = min([child.lineno] + [d.lineno for d in child.decorator_list])
                        above = []
                        i = first - 2
                        while i >= 0 and lines[i].lstrip().startswith("#"):
                            above.append(lines[i].strip())
                            i -= 1
                        found.append((name, length, any(c.startswith(LONG_MARK)
                                                        for c in above)))
                visit(child, f"{name}.")
            else:
                visit(child, prefix)

    visit(ast.parse("\n".join(lines)), "")
    return found


def package_files() -> list[Path]:
    return [p for p in sorted(PACKAGE.rglob("*.py")) if KERNELS not in p.parents]


def test_the_scan_finds_a_long_function_and_its_mark(tmp_path):
    """The scan counts a function's lines, sees methods and nested functions, and reads
    the mark above a def or its decorators (if it saw nothing, the test below would pass
    for nothing)."""
    def body(indent: int) -> str:
        return "\n".join([" " * indent + "x = 0"] * MAX_LINES)

    (tmp_path / "m.py").write_text(
        f"def short():\n    pass\n\n\ndef long_one():\n{body(4)}\n\n\n"
        f"class C:\n    # long: the reason\n    @staticmethod\n    def kept():\n{body(8)}\n"
        f"\n    def nested(self):\n        def inner():\n{body(12)}\n", encoding="utf-8")
    assert long_functions(tmp_path / "m.py") == [
        ("long_one", MAX_LINES + 1, False), ("C.kept", MAX_LINES + 1, True),
        ("C.nested", MAX_LINES + 2, False), ("C.nested.inner", MAX_LINES + 1, False)]


def test_no_function_outside_the_kernels_is_longer_than_the_limit_without_a_reason():
    """Every function of src/wovenimpact outside kernels/ is at most MAX_LINES lines long,
    or says why above its def (LONG_MARK), or is in PENDING."""
    bad = []
    for path in package_files():
        where = path.relative_to(PACKAGE).as_posix()
        for name, length, marked in long_functions(path):
            if not marked and f"{where}:{name}" not in PENDING:
                bad.append(f"src/wovenimpact/{where}: {name} is {length} lines (at most "
                           f"{MAX_LINES}: split it into helpers that each build one thing, "
                           f"or say why above its def with '{LONG_MARK} …')")
    assert not bad, "\n".join(bad)


def test_every_pending_function_is_still_long():
    """PENDING only shrinks: an entry whose function has been split (or removed) fails."""
    long = {f"{p.relative_to(PACKAGE).as_posix()}:{name}"
            for p in package_files() for name, _, _ in long_functions(p)}
    assert sorted(set(PENDING) - long) == []
