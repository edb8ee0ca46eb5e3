"""Calls of the kernels from outside ``kernels/``: bundles, not long positional lists.

A kernel that takes two dozen positional arrays compiles and runs with two of them
swapped. So every call from the package outside ``src/wovenimpact/kernels/``, and from
``benchmarks/``, to a function defined in ``kernels/`` passes at most MAX_ARGS arguments
(the rest grouped in the named tuples of ``kernels/bundles.py``) and no bare literal
(a number or True/False) positionally: a named constant, a keyword or a bundle built with
keywords says what the value is.

Kernels calling kernels inside ``kernels/`` may keep long signatures: a stage inlined
into a parallel loop takes that loop's locals (a bundle written through in the loop body
can lose its writes: kernels/bundles.py); such a kernel says so in a comment above its
``def`` containing KEEP_MARK. Compiled code outside ``kernels/`` that copies a kernel's
loop (``@njit`` functions of benchmarks/) may call those stages as the kernel does. The
tests call the inner stages of a kernel directly, to check them alone; they may pass
literals, and call a stage with more than MAX_ARGS arguments only where the kernel keeps
its long signature on purpose.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "wovenimpact"
KERNELS = PACKAGE / "kernels"
MAX_ARGS = 12
KEEP_MARK = "keeps its long signature"


def kernel_functions() -> dict[str, dict[str, bool]]:
    """{kernel module: {function: whether a comment above its def says it keeps a long
    signature (KEEP_MARK)}} of the top-level functions of kernels/."""
    found = {}
    for path in sorted(KERNELS.glob("*.py")):
        lines = path.read_text().splitlines()
        functions = {}
        for node in ast.parse("\n".join(lines)).body:
            if isinstance(node, ast.FunctionDef):
                first = min([node.lineno] + [d.lineno for d in node.decorator_list])
                above = []
                i = first - 2
                while i >= 0 and lines[i].lstrip().startswith("#"):
                    above.append(lines[i])
                    i -= 1
                functions[node.name] = KEEP_MARK in " ".join(above)
        found[path.stem] = functions
    return found


def kernel_names(tree: ast.Module) -> tuple[dict[str, tuple[str, str]], dict[str, str]]:
    """The names a module binds to kernel functions, {name: (kernel module, function)},
    and to kernel modules, {name: kernel module}; imports inside functions included."""
    functions, modules = {}, {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            parts = node.module.split(".")
            if "kernels" not in parts:
                continue
            if parts[-1] == "kernels":
                for alias in node.names:
                    modules[alias.asname or alias.name] = alias.name
            else:
                for alias in node.names:
                    functions[alias.asname or alias.name] = (parts[-1], alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                parts = alias.name.split(".")
                if len(parts) >= 2 and parts[-2] == "kernels" and alias.asname:
                    modules[alias.asname] = parts[-1]
    return functions, modules


def tuple_lengths(tree: ast.Module) -> dict[str, int]:
    """{name: its length} of the names assigned a tuple display in a module (to count
    the arguments of a call ``f(*args)``); a name assigned twice is not counted."""
    lengths: dict[str, int] = {}
    seen: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
            if isinstance(target, ast.Name):
                if target.id in seen:
                    lengths.pop(target.id, None)
                elif isinstance(node.value, ast.Tuple):
                    lengths[target.id] = len(node.value.elts)
                seen.add(target.id)
    return lengths


def is_bare_literal(arg: ast.expr) -> bool:
    """A number, True or False written as it is (also −1, +2.5)."""
    if isinstance(arg, ast.UnaryOp) and isinstance(arg.op, (ast.USub, ast.UAdd)):
        arg = arg.operand
    return isinstance(arg, ast.Constant) and isinstance(arg.value, (bool, int, float, complex))


def compiled_calls(tree: ast.Module) -> set[int]:
    """The ids of the calls made inside functions compiled by Numba (decorated with
    ``njit``/``jit``, bare, called or as ``numba.njit``)."""
    inside = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef):
            for d in node.decorator_list:
                target = d.func if isinstance(d, ast.Call) else d
                name = target.attr if isinstance(target, ast.Attribute) else getattr(
                    target, "id", "")
                if name in ("njit", "jit"):
                    inside.update(id(c) for c in ast.walk(node) if isinstance(c, ast.Call))
    return inside


def kernel_calls(path: Path, kernels: dict[str, dict[str, bool]]):
    """(line, kernel module, function, number of arguments, bare literals passed
    positionally, whether the call is in compiled code) of every call of a kernel
    function in the file at ``path``."""
    tree = ast.parse(path.read_text())
    functions, modules = kernel_names(tree)
    lengths = tuple_lengths(tree)
    compiled = compiled_calls(tree)
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name) and f.id in functions:
            module, name = functions[f.id]
        elif (isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name)
              and f.value.id in modules):
            module, name = modules[f.value.id], f.attr
        else:
            continue
        if name not in kernels.get(module, {}):
            continue  # a class (a bundle), a constant or a name of no kernel module
        count = len(node.keywords)
        for arg in node.args:
            if isinstance(arg, ast.Starred):
                value = arg.value
                count += lengths.get(value.id, 1) if isinstance(value, ast.Name) else 1
            else:
                count += 1
        literals = [ast.unparse(a) for a in node.args if is_bare_literal(a)]
        yield node.lineno, module, name, count, literals, id(node) in compiled


def callers(tests: bool) -> list[Path]:
    """The files that call kernels from outside: the package and benchmarks/, or tests/."""
    if tests:
        return sorted((ROOT / "tests").rglob("*.py"))
    package = [p for p in sorted(PACKAGE.rglob("*.py")) if KERNELS not in p.parents]
    return package + sorted((ROOT / "benchmarks").glob("*.py"))


def test_the_scan_sees_the_calls_it_checks():
    """The scan finds the kernel calls of the solver and of the contact's driver (if it
    saw none, the tests below would pass for nothing)."""
    kernels = kernel_functions()
    found = {(c[1], c[2]) for p in callers(tests=False) for c in kernel_calls(p, kernels)}
    for call in [("contact_rigid", "rigid_contact_forces"), ("contact_narrow", "penalty_forces"),
                 ("contact_broad", "query_candidates"), ("shell", "internal_force_for_shells"),
                 ("integrate", "gather_and_update"), ("shell_blocks", "element_lanes")]:
        assert call in found, call


def test_no_kernel_is_called_from_outside_with_many_arguments_or_bare_literals():
    """At most MAX_ARGS arguments and no bare literal passed positionally in a call of a
    kernel from the package (outside kernels/) or from benchmarks/ (more only from
    compiled code, to a stage that keeps its long signature)."""
    kernels = kernel_functions()
    bad = []
    for path in callers(tests=False):
        for line, module, name, count, literals, compiled in kernel_calls(path, kernels):
            where = f"{path.relative_to(ROOT)}:{line} {module}.{name}"
            if count > MAX_ARGS and not (compiled and kernels[module][name]):
                bad.append(f"{where}: {count} arguments (at most {MAX_ARGS}: pass bundles, "
                           "kernels/bundles.py)")
            if literals:
                bad.append(f"{where}: bare literals {', '.join(literals)} passed positionally "
                           "(name them: a constant, a keyword or a bundle)")
    assert not bad, "\n".join(bad)


def test_tests_call_long_signatures_only_where_the_kernel_keeps_them_on_purpose():
    """A test may call an inner stage with more than MAX_ARGS arguments only if the
    kernel says, above its def, why it keeps that signature (KEEP_MARK)."""
    kernels = kernel_functions()
    bad = []
    for path in callers(tests=True):
        for line, module, name, count, _, _ in kernel_calls(path, kernels):
            if count > MAX_ARGS and not kernels[module][name]:
                bad.append(f"{path.relative_to(ROOT)}:{line} {module}.{name}: {count} "
                           f"arguments, and no '# … {KEEP_MARK} …' above its def")
    assert not bad, "\n".join(bad)
